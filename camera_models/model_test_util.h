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

#include <ceres/ceres.h>

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

// The Jacobians Ceres' autodiff gives of Model's projection at `ray` and of
// its unprojection at the resulting pixel, with respect to the ray or pixel
// and to the parameters, against central differences (`steps` per
// parameter, empty for the default).
template <typename Model>
void ExpectAutodiffMatchesCentralDifferences(const std::vector<double>& params,
                                             const Eigen::Vector3d& ray,
                                             const std::vector<double>& steps) {
  constexpr int N = Model::kNumParams;
  using RowMajor =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  ceres::AutoDiffCostFunction<ImageFromRayFunctor<Model>, 2, 3, N> project(
      new ImageFromRayFunctor<Model>);
  ceres::AutoDiffCostFunction<RayFromImageFunctor<Model>, 3, 2, N> unproject(
      new RayFromImageFunctor<Model>);
  Eigen::Vector2d pixel;
  RowMajor d_ray(2, 3), d_params(2, N);
  {
    const double* blocks[2] = {ray.data(), params.data()};
    double* jacobians[2] = {d_ray.data(), d_params.data()};
    ASSERT_TRUE(project.Evaluate(blocks, pixel.data(), jacobians));
  }
  ExpectJacobianNear(d_ray,
                           CentralDifferences(
                               [&](const std::vector<double>& r) {
                                 Eigen::VectorXd p(2);
                                 EXPECT_TRUE(Model::ImageFromRay(
                                     params.data(), r.data(), p.data()));
                                 return p;
                               },
                               {ray.x(), ray.y(), ray.z()}, 2),
                           "ImageFromRay d/dray");
  ExpectJacobianNear(
      d_params,
      CentralDifferences(
          [&](const std::vector<double>& q) {
            Eigen::VectorXd p(2);
            EXPECT_TRUE(Model::ImageFromRay(q.data(), ray.data(), p.data()));
            return p;
          },
          params, 2, steps),
      "ImageFromRay d/dparams");

  Eigen::Vector3d back;
  RowMajor u_pixel(3, 2), u_params(3, N);
  {
    const double* blocks[2] = {pixel.data(), params.data()};
    double* jacobians[2] = {u_pixel.data(), u_params.data()};
    ASSERT_TRUE(unproject.Evaluate(blocks, back.data(), jacobians));
  }
  ExpectJacobianNear(u_pixel,
                           CentralDifferences(
                               [&](const std::vector<double>& p) {
                                 Eigen::VectorXd r(3);
                                 EXPECT_TRUE(Model::RayFromImage(
                                     params.data(), p.data(), r.data()));
                                 return r;
                               },
                               {pixel.x(), pixel.y()}, 3),
                           "RayFromImage d/dpixel");
  ExpectJacobianNear(u_params,
                           CentralDifferences(
                               [&](const std::vector<double>& q) {
                                 Eigen::VectorXd r(3);
                                 EXPECT_TRUE(Model::RayFromImage(
                                     q.data(), pixel.data(), r.data()));
                                 return r;
                               },
                               params, 3, steps),
                           "RayFromImage d/dparams");
}

// Whether a dense scan of the image circle a width x height frame shows
// (every 4 px inside it and 720 points of its rim) finds only pixels whose
// rays lie in front of the image plane or that have no ray: the reference
// for FieldInFrontOfImagePlane.
template <typename Model>
bool ScannedFieldInFront(const std::vector<double>& params, int width,
                         int height) {
  const double fx = params[0], fy = params[1], cx = params[2], cy = params[3];
  const double radius =
      internal::FrameCircleRadius(params.data(), width, height);
  std::vector<Eigen::Vector2d> pixels;
  for (double px = cx - radius * fx; px <= cx + radius * fx; px += 4) {
    for (double py = cy - radius * fy; py <= cy + radius * fy; py += 4) {
      if (std::hypot((px - cx) / fx, (py - cy) / fy) <= radius) {
        pixels.emplace_back(px, py);
      }
    }
  }
  for (int i = 0; i < 720; ++i) {
    const double phi = i * M_PI / 360;
    pixels.emplace_back(cx + radius * fx * std::cos(phi),
                        cy + radius * fy * std::sin(phi));
  }
  for (const Eigen::Vector2d& pixel : pixels) {
    double ray[3];
    if (Model::RayFromImage(params.data(), pixel.data(), ray) && ray[2] <= 0) {
      return false;
    }
  }
  return true;
}

// Frames of sizes whose image circles reach from well inside to well beyond
// 90° off the axis (350 to 550 px about the centre) for lenses of focal
// length ~300 px, each with the principal point near its centre:
// FieldInFrontOfImagePlane must agree with the scan on each, and both
// answers must occur.
template <typename Model>
void ExpectFieldInFrontMatchesScan(std::vector<double> params) {
  int in_front = 0;
  int behind = 0;
  for (int width = 700; width <= 1100; width += 16) {
    for (int height : {480, 900, 1000}) {
      params[2] = width / 2.0 + 0.3;
      params[3] = height / 2.0 + 0.2;
      const bool expected = ScannedFieldInFront<Model>(params, width, height);
      EXPECT_EQ(Model::FieldInFrontOfImagePlane(params.data(), width, height),
                expected)
          << width << " x " << height;
      (expected ? in_front : behind) += 1;
    }
  }
  EXPECT_GT(in_front, 0);
  EXPECT_GT(behind, 0);
}

}  // namespace test
}  // namespace sphera
