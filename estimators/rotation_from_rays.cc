#include "estimators/rotation_from_rays.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

namespace sphera {
namespace {

// The orthonormal frame (columns) of two non-parallel unit rays a, b:
// a, the normal of their plane, and the third axis.
bool TriadOfRays(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 Eigen::Matrix3d* triad) {
  const Eigen::Vector3d normal = a.cross(b);
  const double norm = normal.norm();
  // Rays less than ~0.5° apart define no plane worth sampling.
  if (norm < 1e-2) {
    return false;
  }
  triad->col(0) = a;
  triad->col(1) = normal / norm;
  triad->col(2) = a.cross(triad->col(1));
  return true;
}

int CountInliers(const std::vector<Eigen::Vector3d>& rays_in_cam1,
                 const std::vector<Eigen::Vector3d>& rays_in_cam2,
                 const Eigen::Matrix3d& cam2_from_cam1, double min_cosine,
                 std::vector<char>* inlier_mask) {
  int num_inliers = 0;
  inlier_mask->assign(rays_in_cam1.size(), 0);
  for (size_t i = 0; i < rays_in_cam1.size(); ++i) {
    if (rays_in_cam2[i].dot(cam2_from_cam1 * rays_in_cam1[i]) > min_cosine) {
      (*inlier_mask)[i] = 1;
      ++num_inliers;
    }
  }
  return num_inliers;
}

}  // namespace

void RotationFromRaysOptions::Check() const {
  if (!(max_error_rad > 0 && max_error_rad < 3.14159265358979323846)) {
    throw std::invalid_argument(
        "max_error_rad must be in (0, pi), got " +
        std::to_string(max_error_rad));
  }
  if (max_num_trials < 1) {
    throw std::invalid_argument("max_num_trials must be at least 1, got " +
                                std::to_string(max_num_trials));
  }
  if (!(confidence > 0 && confidence < 1)) {
    throw std::invalid_argument("confidence must be in (0, 1), got " +
                                std::to_string(confidence));
  }
  if (min_num_inliers < 2) {
    throw std::invalid_argument("min_num_inliers must be at least 2, got " +
                                std::to_string(min_num_inliers));
  }
}

Eigen::Matrix3d FitRotationToRays(
    const std::vector<Eigen::Vector3d>& rays_in_cam1,
    const std::vector<Eigen::Vector3d>& rays_in_cam2) {
  if (rays_in_cam1.size() < 2 || rays_in_cam1.size() != rays_in_cam2.size()) {
    return Eigen::Matrix3d::Identity();
  }
  Eigen::Matrix3d correlation = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < rays_in_cam1.size(); ++i) {
    correlation += rays_in_cam2[i] * rays_in_cam1[i].transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      correlation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d sign = Eigen::Matrix3d::Identity();
  sign(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0
                   ? -1
                   : 1;
  return svd.matrixU() * sign * svd.matrixV().transpose();
}

RotationFromRays EstimateRotationFromRays(
    const std::vector<Eigen::Vector3d>& rays_in_cam1,
    const std::vector<Eigen::Vector3d>& rays_in_cam2,
    const RotationFromRaysOptions& options) {
  options.Check();
  if (rays_in_cam1.size() != rays_in_cam2.size()) {
    throw std::invalid_argument(
        "EstimateRotationFromRays: " + std::to_string(rays_in_cam1.size()) +
        " rays in camera 1 but " + std::to_string(rays_in_cam2.size()) +
        " in camera 2");
  }
  RotationFromRays result;
  const int num_rays = static_cast<int>(rays_in_cam1.size());
  if (num_rays < std::max(2, options.min_num_inliers)) {
    return result;
  }
  const double min_cosine = std::cos(options.max_error_rad);
  std::mt19937 rng(options.random_seed);
  std::uniform_int_distribution<int> pick(0, num_rays - 1);
  std::vector<char> mask;
  int best_num_inliers = 0;
  Eigen::Matrix3d best = Eigen::Matrix3d::Identity();
  int num_trials_needed = options.max_num_trials;
  for (int trial = 0; trial < std::min(options.max_num_trials,
                                       num_trials_needed);
       ++trial) {
    const int i = pick(rng);
    const int j = pick(rng);
    Eigen::Matrix3d triad1, triad2;
    if (i == j || !TriadOfRays(rays_in_cam1[i], rays_in_cam1[j], &triad1) ||
        !TriadOfRays(rays_in_cam2[i], rays_in_cam2[j], &triad2)) {
      continue;
    }
    // The angle between the two rays is kept by any rotation: a sample
    // whose angles differ by more than twice the threshold has an outlier.
    if (std::abs(std::acos(std::clamp(rays_in_cam1[i].dot(rays_in_cam1[j]),
                                      -1.0, 1.0)) -
                 std::acos(std::clamp(rays_in_cam2[i].dot(rays_in_cam2[j]),
                                      -1.0, 1.0))) >
        2 * options.max_error_rad) {
      continue;
    }
    const Eigen::Matrix3d cam2_from_cam1 = triad2 * triad1.transpose();
    const int num_inliers = CountInliers(rays_in_cam1, rays_in_cam2,
                                         cam2_from_cam1, min_cosine, &mask);
    if (num_inliers > best_num_inliers) {
      best_num_inliers = num_inliers;
      best = cam2_from_cam1;
      const double inlier_ratio =
          static_cast<double>(num_inliers) / num_rays;
      const double p_good_sample = inlier_ratio * inlier_ratio;
      num_trials_needed =
          p_good_sample >= 1
              ? 1
              : static_cast<int>(std::ceil(std::log(1 - options.confidence) /
                                           std::log(1 - p_good_sample)));
    }
  }
  if (best_num_inliers < options.min_num_inliers) {
    return result;
  }
  // Refit on the inliers, re-select them under the refined rotation, once
  // more refit: the minimal sample's noise no longer decides the inlier set.
  for (int round = 0; round < 2; ++round) {
    CountInliers(rays_in_cam1, rays_in_cam2, best, min_cosine, &mask);
    std::vector<Eigen::Vector3d> inliers1, inliers2;
    for (int i = 0; i < num_rays; ++i) {
      if (mask[i]) {
        inliers1.push_back(rays_in_cam1[i]);
        inliers2.push_back(rays_in_cam2[i]);
      }
    }
    if (static_cast<int>(inliers1.size()) < options.min_num_inliers) {
      return result;
    }
    best = FitRotationToRays(inliers1, inliers2);
  }
  result.num_inliers = CountInliers(rays_in_cam1, rays_in_cam2, best,
                                    min_cosine, &result.inlier_mask);
  result.success = result.num_inliers >= options.min_num_inliers;
  result.cam2_from_cam1 = best;
  return result;
}

}  // namespace sphera
