// Enhanced unified camera model (Khomutenko et al. 2016), id 16, parameter
// order as upstream COLMAP 4.1: fx, fy, cx, cy, alpha, beta.
//
//   d = sqrt(beta (x² + y²) + z²),  den = alpha d + (1 - alpha) z
//   px = fx x / den + cx,           py = fy y / den + cy
//
// Field of view (Usenko et al. 2018, eq. for EUCM): the ray is visible iff
//   z > -w d,  w = alpha / (1 - alpha) if alpha <= 0.5 else (1 - alpha) / alpha.
// EUCM(x, y, z) equals the unified model with xi = alpha / (1 - alpha) applied
// to (sqrt(beta) x, sqrt(beta) y, z); for xi <= 1 the condition is den > 0, for
// xi > 1 it stops at the ray tangent to the unit sphere seen from (0, 0, -xi),
// where the image radius is maximal, i.e. Omega is the largest set on which the
// projection is injective (checked numerically in camera_models_test.cc).
// Pixel domain: m² = ((px-cx)/fx)² + ((py-cy)/fy)² <= 1 / (beta (2 alpha - 1))
// when alpha > 0.5, the whole plane otherwise.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "camera_models/common.h"

namespace sphera {

struct EUCMModel {
  static constexpr int kModelId = 16;
  static constexpr const char* kModelName = "EUCM";
  static constexpr int kNumParams = 6;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, alpha, beta";
  static constexpr std::array<int, 2> kFocalLengthIdxs = {0, 1};
  static constexpr std::array<int, 2> kPrincipalPointIdxs = {2, 3};
  static constexpr std::array<int, 2> kExtraParamsIdxs = {4, 5};
  static constexpr std::array<int, 0> kFixedParamsIdxs = {};

  static std::vector<double> InitialParams(double focal_length, int width,
                                           int height) {
    return {focal_length, focal_length, width / 2.0, height / 2.0, 0.5, 1.0};
  }

  template <typename T>
  static bool ImageFromRay(const T* params, const T* ray_in_cam, T* pixel) {
    using std::sqrt;
    const T& alpha = params[4];
    const T& beta = params[5];
    const T& x = ray_in_cam[0];
    const T& y = ray_in_cam[1];
    const T& z = ray_in_cam[2];
    const T d2 = beta * (x * x + y * y) + z * z;
    if (!(d2 > T(0))) return false;
    const T d = sqrt(d2);
    const T den = alpha * d + (T(1) - alpha) * z;
    if (den == T(0)) return false;
    pixel[0] = params[0] * x / den + params[2];
    pixel[1] = params[1] * y / den + params[3];
    const T w = alpha <= T(0.5) ? alpha / (T(1) - alpha)
                                : (T(1) - alpha) / alpha;
    return den > T(0) && z > -w * d;
  }

  // mz = (1 - beta alpha² r²) / (alpha sqrt(1 - (2 alpha - 1) beta r²) + 1 - alpha)
  // ray = normalize(mx, my, mz).
  template <typename T>
  static bool RayFromImage(const T* params, const T* pixel, T* ray_in_cam) {
    using std::sqrt;
    const T& alpha = params[4];
    const T& beta = params[5];
    const T mx = (pixel[0] - params[2]) / params[0];
    const T my = (pixel[1] - params[3]) / params[1];
    const T r2 = mx * mx + my * my;
    const T gamma = (T(2) * alpha - T(1)) * beta * r2;
    // gamma > 1 only for alpha > 0.5: outside r² <= 1 / (beta (2 alpha - 1)).
    if (gamma > T(1)) return false;
    const T den = alpha * sqrt(T(1) - gamma) + (T(1) - alpha);
    if (!(den > T(0))) return false;
    const T mz = (T(1) - beta * alpha * alpha * r2) / den;
    return internal::NormalizeRay(mx, my, mz, ray_in_cam);
  }

  // Whether every pixel of the image circle a width x height frame shows
  // (common.h, FrameCircleRadius) sees a ray with z > 0: the image radius of
  // the rays with z = 0 is 1 / (alpha sqrt(beta)) (infinite for alpha = 0,
  // the pinhole), and |m| grows with the angle from the axis.
  static bool FieldInFrontOfImagePlane(const double* params, int width,
                                       int height) {
    if (width <= 0 || height <= 0) return false;
    return params[4] * std::sqrt(params[5]) *
               internal::FrameCircleRadius(params, width, height) <
           1.0;
  }

  // Near the axis d ~ z and den ~ z: a pinhole with focal mean(fx, fy).
  static double PixelToAngle(const double* params) {
    return 2.0 / (params[0] + params[1]);
  }

  static std::string CheckParams(const std::vector<double>& params,
                                 int /*width*/, int /*height*/) {
    using namespace internal;
    if (auto e = CheckCountFiniteFocal(kModelName, kParamsInfo, kNumParams,
                                       params);
        !e.empty())
      return e;
    if (auto e = CheckInRange(kModelName, kParamsInfo, params, 4, 0.0, false,
                              1.0, false);
        !e.empty())
      return e;
    return CheckPositive(kModelName, kParamsInfo, params, 5);
  }
};

}  // namespace sphera
