// Synthetic data helpers for the estimator tests (deterministic seeds).
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimators/eigen_types.h"

namespace sphera {
namespace test {

// Uniform direction on S^2.
inline Eigen::Vector3d RandomUnitVector(std::mt19937* rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Vector3d v;
  do {
    v = Eigen::Vector3d(n(*rng), n(*rng), n(*rng));
  } while (v.norm() < 1e-6);
  return v.normalized();
}

inline Eigen::Matrix3d RandomRotation(std::mt19937* rng,
                                      double max_angle = M_PI) {
  std::uniform_real_distribution<double> u(0, max_angle);
  return Eigen::AngleAxisd(u(*rng), RandomUnitVector(rng)).toRotationMatrix();
}

// Unit vector orthogonal to u (random direction in its tangent plane).
inline Eigen::Vector3d RandomTangent(const Eigen::Vector3d& u,
                                     std::mt19937* rng) {
  Eigen::Vector3d w;
  do {
    w = u.cross(RandomUnitVector(rng));
  } while (w.norm() < 1e-3);
  return w.normalized();
}

// Rotate the unit ray u by `angle` in a random tangent direction.
inline Eigen::Vector3d PerturbRay(const Eigen::Vector3d& u, double angle,
                                  std::mt19937* rng) {
  const Eigen::Vector3d w = RandomTangent(u, rng);
  return (std::cos(angle) * u + std::sin(angle) * w).normalized();
}

// Ray perturbed by isotropic Gaussian tangent noise of std sigma [rad] per axis.
inline Eigen::Vector3d NoisyRay(const Eigen::Vector3d& u, double sigma,
                                std::mt19937* rng) {
  if (sigma <= 0) return u;
  std::normal_distribution<double> n(0, sigma);
  const Eigen::Vector3d w1 = RandomTangent(u, rng);
  const Eigen::Vector3d w2 = u.cross(w1);
  const Eigen::Vector3d d = n(*rng) * w1 + n(*rng) * w2;
  const double angle = d.norm();
  if (angle == 0) return u;
  return (std::cos(angle) * u + std::sin(angle) * d / angle).normalized();
}

inline Eigen::Matrix3x4d MakePose(const Eigen::Matrix3d& R,
                                  const Eigen::Vector3d& t) {
  Eigen::Matrix3x4d P;
  P.leftCols<3>() = R;
  P.col(3) = t;
  return P;
}

inline double RotationErrorRad(const Eigen::Matrix3d& R1,
                               const Eigen::Matrix3d& R2) {
  return Eigen::AngleAxisd(R1.transpose() * R2).angle();
}

}  // namespace test
}  // namespace sphera
