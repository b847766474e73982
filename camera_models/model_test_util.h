// Helpers shared by the camera model tests: ray geometry and the comparison of
// autodiff Jacobians (ceres::AutoDiffCostFunction over a model) with central
// differences.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

namespace sphera {
namespace test {

// Angle between two rays without acos: atan2(|a x b|, a . b).
inline double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// Ray at polar angle theta from +z and azimuth phi around it.
inline Eigen::Vector3d RayAt(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
          std::cos(theta)};
}

template <typename Model>
struct ImageFromRayFunctor {
  template <typename T>
  bool operator()(const T* ray_in_cam, const T* params, T* pixel) const {
    return Model::ImageFromRay(params, ray_in_cam, pixel);
  }
};

template <typename Model>
struct RayFromImageFunctor {
  template <typename T>
  bool operator()(const T* pixel, const T* params, T* ray_in_cam) const {
    return Model::RayFromImage(params, pixel, ray_in_cam);
  }
};

// Fourth-order central differences of f: R^n -> R^m at x,
//   f' ~ (f(x - 2h) - 8 f(x - h) + 8 f(x + h) - f(x + 2h)) / 12h,
// with h = 1e-4 max(1, |x_i|) unless steps gives h per variable (for
// variables of very different scales): truncation O(h^4), rounding O(eps / h).
template <typename Func>
Eigen::MatrixXd CentralDifferences(const Func& f, std::vector<double> x,
                                   int num_outputs,
                                   const std::vector<double>& steps = {}) {
  Eigen::MatrixXd jacobian(num_outputs, x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    const double x0 = x[i];
    const double h =
        steps.empty() ? 1e-4 * std::max(1.0, std::abs(x0)) : steps[i];
    auto at = [&](double offset) {
      x[i] = x0 + offset;
      return Eigen::VectorXd(f(x));
    };
    jacobian.col(i) =
        (at(-2 * h) - 8 * at(-h) + 8 * at(h) - at(2 * h)) / (12 * h);
    x[i] = x0;
  }
  return jacobian;
}

// Each column must match to 1e-6 relative (floored at 1e-3 of the matrix norm
// so that exactly-zero columns compare absolutely).
inline void ExpectJacobianNear(const Eigen::MatrixXd& autodiff,
                               const Eigen::MatrixXd& numeric,
                               const char* what) {
  const double floor = 1e-3 * autodiff.norm();
  for (int c = 0; c < autodiff.cols(); ++c) {
    const double scale = std::max(autodiff.col(c).norm(), floor);
    EXPECT_LE((autodiff.col(c) - numeric.col(c)).norm(), 1e-6 * scale)
        << what << " column " << c << "\nautodiff\n"
        << autodiff << "\nnumeric\n"
        << numeric;
  }
}

}  // namespace test
}  // namespace sphera
