// Double sphere model (Usenko, Demmel, Cremers 2018), id 65:
//   fx, fy, cx, cy, xi, alpha
//
//   d1 = |X|,  d2 = sqrt(x² + y² + (xi d1 + z)²)
//   den = alpha d2 + (1 - alpha) (xi d1 + z),  px = fx x / den + cx
// Visible iff the second (EUCM-like) stage sees the shifted point
// q = (x, y, xi d1 + z) inside its own field of view:
//   xi d1 + z > -w1 d2,  w1 = alpha / (1 - alpha) if alpha <= 0.5
//                              else (1 - alpha) / alpha,
// which for |X| = 1 is z > -(xi (1 - w1²) + w1 sqrt(1 - xi² + xi² w1²)).
// This is the exact limit of injectivity (for alpha <= 0.5 it is den > 0, for
// alpha > 0.5 the image radius is maximal there). Usenko et al.'s closed form
// z > -w2 d1, w2 = (w1 + xi) / sqrt(2 w1 xi + xi² + 1), agrees only for xi = 0
// and otherwise rejects valid rays (e.g. 24 deg of polar angle at xi = 0.9,
// alpha = 0.7); camera_models_test.cc checks the limit numerically.
// Unprojection, m = ((px-cx)/fx, (py-cy)/fy), r² = |m|²:
//   mz = (1 - alpha² r²) / (alpha sqrt(1 - (2 alpha - 1) r²) + 1 - alpha)
//   ray = normalize(((mz xi + sqrt(mz² + (1 - xi²) r²)) / (mz² + r²)) (mx, my, mz)
//                   - (0, 0, xi))
// Pixel domain: r² <= 1 / (2 alpha - 1) when alpha > 0.5.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "camera_models/common.h"

namespace sphera {

struct DoubleSphereModel {
  static constexpr int kModelId = 65;
  static constexpr const char* kModelName = "DOUBLE_SPHERE";
  static constexpr int kNumParams = 6;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, xi, alpha";
  static constexpr std::array<int, 2> kFocalLengthIdxs = {0, 1};
  static constexpr std::array<int, 2> kPrincipalPointIdxs = {2, 3};
  static constexpr std::array<int, 2> kExtraParamsIdxs = {4, 5};
  static constexpr std::array<int, 0> kFixedParamsIdxs = {};

  static std::vector<double> InitialParams(double focal_length, int width,
                                           int height) {
    return {focal_length, focal_length, width / 2.0, height / 2.0, 0.0, 0.5};
  }

  template <typename T>
  static bool ImageFromRay(const T* params, const T* ray_in_cam, T* pixel) {
    using std::sqrt;
    const T& xi = params[4];
    const T& alpha = params[5];
    const T& x = ray_in_cam[0];
    const T& y = ray_in_cam[1];
    const T& z = ray_in_cam[2];
    const T rho2 = x * x + y * y;
    const T d1_2 = rho2 + z * z;
    if (!(d1_2 > T(0))) return false;
    const T d1 = sqrt(d1_2);
    const T z_shifted = xi * d1 + z;
    const T d2 = sqrt(rho2 + z_shifted * z_shifted);
    const T den = alpha * d2 + (T(1) - alpha) * z_shifted;
    if (den == T(0)) return false;
    pixel[0] = params[0] * x / den + params[2];
    pixel[1] = params[1] * y / den + params[3];
    const T w1 = alpha <= T(0.5) ? alpha / (T(1) - alpha)
                                 : (T(1) - alpha) / alpha;
    return den > T(0) && z_shifted > -w1 * d2;
  }

  template <typename T>
  static bool RayFromImage(const T* params, const T* pixel, T* ray_in_cam) {
    using std::sqrt;
    const T& xi = params[4];
    const T& alpha = params[5];
    const T mx = (pixel[0] - params[2]) / params[0];
    const T my = (pixel[1] - params[3]) / params[1];
    const T r2 = mx * mx + my * my;
    const T gamma = (T(2) * alpha - T(1)) * r2;
    // gamma > 1 only for alpha > 0.5: outside r² <= 1 / (2 alpha - 1).
    if (gamma > T(1)) return false;
    const T mz_den = alpha * sqrt(T(1) - gamma) + T(1) - alpha;
    if (!(mz_den > T(0))) return false;
    const T mz = (T(1) - alpha * alpha * r2) / mz_den;
    const T norm2 = mz * mz + r2;
    const T disc = mz * mz + (T(1) - xi * xi) * r2;
    if (!(norm2 > T(0)) || disc < T(0)) return false;
    const T k = (mz * xi + sqrt(disc)) / norm2;
    return internal::NormalizeRay(k * mx, k * my, k * mz - xi, ray_in_cam);
  }

  // Near the axis den ~ (1 + xi) z.
  static double PixelToAngle(const double* params) {
    return (1.0 + params[4]) * 2.0 / (params[0] + params[1]);
  }

  static std::string CheckParams(const std::vector<double>& params,
                                 int /*width*/, int /*height*/) {
    using namespace internal;
    if (auto e = CheckCountFiniteFocal(kModelName, kParamsInfo, kNumParams,
                                       params);
        !e.empty())
      return e;
    if (auto e = CheckInRange(kModelName, kParamsInfo, params, 4, -1.0, true,
                              1.0, false);
        !e.empty())
      return e;
    return CheckInRange(kModelName, kParamsInfo, params, 5, 0.0, false, 1.0,
                        false);
  }
};

}  // namespace sphera
