// Mei's unified omnidirectional model with radial-tangential distortion, id 64
// (Kalibr "omni-radtan", OpenCV cv::omnidir without skew).
//
// Parameter order follows cv::omnidir (K, then xi, then D):
//   fx, fy, cx, cy, xi, k1, k2, p1, p2
// Kalibr stores the same values as intrinsics [xi, fu, fv, pu, pv] and
// distortion_coeffs [k1, k2, r1, r2] (r1 = p1, r2 = p2).
//
// Projection: s = ray / |ray|, m = (sx, sy) / (sz + xi), (mdx, mdy) = radtan(m)
// with the OPENCV distortion (see perspective.h), px = fx mdx + cx.
// Visible iff sz > -xi for xi <= 1 (den > 0) and sz > -1 / xi for xi > 1 (the
// ray tangent to the unit sphere seen from (0, 0, -xi); beyond it the
// undistorted projection folds back).
// Unprojection of the undistorted m, r² = |m|²:
//   factor = (xi + sqrt(1 + (1 - xi²) r²)) / (r² + 1)
//   ray = normalize(factor mx, factor my, factor - xi)
// The pixel is outside the domain when 1 + (1 - xi²) r² < 0 or the distortion
// cannot be inverted.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "camera_models/common.h"

namespace sphera {

struct UnifiedOmniModel {
  static constexpr int kModelId = 64;
  static constexpr const char* kModelName = "UNIFIED_OMNI";
  static constexpr int kNumParams = 9;
  static constexpr const char* kParamsInfo =
      "fx, fy, cx, cy, xi, k1, k2, p1, p2";
  static constexpr std::array<int, 2> kFocalLengthIdxs = {0, 1};
  static constexpr std::array<int, 2> kPrincipalPointIdxs = {2, 3};
  static constexpr std::array<int, 5> kExtraParamsIdxs = {4, 5, 6, 7, 8};
  static constexpr std::array<int, 0> kFixedParamsIdxs = {};

  static std::vector<double> InitialParams(double focal_length, int width,
                                           int height) {
    return {focal_length, focal_length, width / 2.0, height / 2.0, 1.0,
            0.0,          0.0,          0.0,         0.0};
  }

  template <typename T>
  static bool ImageFromRay(const T* params, const T* ray_in_cam, T* pixel) {
    T s[3];
    if (!internal::NormalizeRay(ray_in_cam[0], ray_in_cam[1], ray_in_cam[2],
                                s)) {
      return false;
    }
    const T& xi = params[4];
    const T den = s[2] + xi;
    if (den == T(0)) return false;
    const T mx = s[0] / den;
    const T my = s[1] / den;
    T mdx, mdy;
    internal::DistortRadTan(params + 5, mx, my, &mdx, &mdy);
    pixel[0] = params[0] * mdx + params[2];
    pixel[1] = params[1] * mdy + params[3];
    return xi <= T(1) ? s[2] > -xi : s[2] * xi > T(-1);
  }

  template <typename T>
  static bool RayFromImage(const T* params, const T* pixel, T* ray_in_cam) {
    using std::sqrt;
    const T& xi = params[4];
    const T mdx = (pixel[0] - params[2]) / params[0];
    const T mdy = (pixel[1] - params[3]) / params[1];
    T mx, my;
    if (!internal::UndistortRadTan(params + 5, mdx, mdy, &mx, &my)) {
      return false;
    }
    const T r2 = mx * mx + my * my;
    const T disc = T(1) + (T(1) - xi * xi) * r2;
    if (disc < T(0)) return false;
    const T factor = (xi + sqrt(disc)) / (r2 + T(1));
    return internal::NormalizeRay(factor * mx, factor * my, factor - xi,
                                  ray_in_cam);
  }

  // Near the axis |m| ~ angle / (1 + xi).
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
    if (params[4] < 0) {
      return std::string(kModelName) + ": xi=" + FormatNumber(params[4]) +
             " must be >= 0";
    }
    return "";
  }
};

}  // namespace sphera
