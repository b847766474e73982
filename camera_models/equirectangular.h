// Equirectangular (longitude/latitude) panorama, id 17, as in COLMAP 4.1.
//
// Ray (x, y, z), camera looking along +z, y pointing down:
//   theta = atan2(x, z)              longitude in [-pi, pi]
//   phi   = atan2(-y, sqrt(x² + z²)) latitude in [-pi/2, pi/2], up positive
//   px = (theta / 2pi + 0.5) W,  py = (0.5 - phi / pi) H
// Pixel (0, 0) is the upper-left image corner; the domain is [0, W] x [0, H].
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "camera_models/common.h"

namespace sphera {

struct EquirectangularModel {
  static constexpr int kModelId = 17;
  static constexpr const char* kModelName = "EQUIRECTANGULAR";
  static constexpr int kNumParams = 2;
  static constexpr const char* kParamsInfo = "w, h";
  static constexpr std::array<int, 0> kFocalLengthIdxs = {};
  static constexpr std::array<int, 0> kPrincipalPointIdxs = {};
  static constexpr std::array<int, 0> kExtraParamsIdxs = {};
  static constexpr std::array<int, 2> kFixedParamsIdxs = {0, 1};

  static std::vector<double> InitialParams(double /*focal_length*/, int width,
                                           int height) {
    return {static_cast<double>(width), static_cast<double>(height)};
  }

  // Every nonzero ray is visible.
  template <typename T>
  static bool ImageFromRay(const T* params, const T* ray_in_cam, T* pixel) {
    using std::atan2;
    using std::sqrt;
    const T& x = ray_in_cam[0];
    const T& y = ray_in_cam[1];
    const T& z = ray_in_cam[2];
    const T horizontal2 = x * x + z * z;
    if (!(horizontal2 + y * y > T(0))) return false;
    const T theta = atan2(x, z);
    const T phi = atan2(-y, sqrt(horizontal2));
    pixel[0] = (theta / T(2 * internal::kPi) + T(0.5)) * params[0];
    pixel[1] = (T(0.5) - phi / T(internal::kPi)) * params[1];
    return true;
  }

  // ray = (cos(phi) sin(theta), -sin(phi), cos(phi) cos(theta)).
  template <typename T>
  static bool RayFromImage(const T* params, const T* pixel, T* ray_in_cam) {
    using std::cos;
    using std::sin;
    const T& width = params[0];
    const T& height = params[1];
    if (!(pixel[0] >= T(0) && pixel[0] <= width && pixel[1] >= T(0) &&
          pixel[1] <= height)) {
      return false;
    }
    const T theta = (pixel[0] / width - T(0.5)) * T(2 * internal::kPi);
    const T phi = (T(0.5) - pixel[1] / height) * T(internal::kPi);
    const T cos_phi = cos(phi);
    ray_in_cam[0] = cos_phi * sin(theta);
    ray_in_cam[1] = -sin(phi);
    ray_in_cam[2] = cos_phi * cos(theta);
    return true;
  }

  // Longitude spans 2pi over W pixels.
  static double PixelToAngle(const double* params) {
    return 2 * internal::kPi / params[0];
  }

  static std::string CheckParams(const std::vector<double>& params, int width,
                                 int height) {
    using namespace internal;
    if (auto e = CheckParamCount(kModelName, kParamsInfo, kNumParams,
                                 params.size());
        !e.empty())
      return e;
    if (auto e = CheckAllFinite(kModelName, kParamsInfo, params); !e.empty())
      return e;
    if (auto e = CheckPositive(kModelName, kParamsInfo, params, 0); !e.empty())
      return e;
    if (auto e = CheckPositive(kModelName, kParamsInfo, params, 1); !e.empty())
      return e;
    const double w = params[0];
    const double h = params[1];
    if (w != 2 * h) {
      return std::string(kModelName) + ": width w=" + FormatNumber(w) +
             " must be twice height h=" + FormatNumber(h);
    }
    if (width > 0 && height > 0 && (w != width || h != height)) {
      return std::string(kModelName) + " params w,h = " + FormatNumber(w) +
             "," + FormatNumber(h) + " differ from the image size " +
             std::to_string(width) + "x" + std::to_string(height);
    }
    return "";
  }
};

}  // namespace sphera
