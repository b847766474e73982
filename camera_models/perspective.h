// COLMAP's PINHOLE (id 1) and OPENCV (id 4) models in the interface of
// this library, for the renderer and for tests that do not link COLMAP.
// A ray is visible iff z > 0.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "camera_models/common.h"

namespace sphera {

// px = fx x / z + cx, py = fy y / z + cy.
struct PinholeModel {
  static constexpr int kModelId = 1;
  static constexpr const char* kModelName = "PINHOLE";
  static constexpr int kNumParams = 4;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy";
  static constexpr std::array<int, 2> kFocalLengthIdxs = {0, 1};
  static constexpr std::array<int, 2> kPrincipalPointIdxs = {2, 3};
  static constexpr std::array<int, 0> kExtraParamsIdxs = {};
  static constexpr std::array<int, 0> kFixedParamsIdxs = {};

  static std::vector<double> InitialParams(double focal_length, int width,
                                           int height) {
    return {focal_length, focal_length, width / 2.0, height / 2.0};
  }

  template <typename T>
  static bool ImageFromRay(const T* params, const T* ray_in_cam, T* pixel) {
    const T& z = ray_in_cam[2];
    if (z == T(0)) return false;
    pixel[0] = params[0] * ray_in_cam[0] / z + params[2];
    pixel[1] = params[1] * ray_in_cam[1] / z + params[3];
    return z > T(0);
  }

  template <typename T>
  static bool RayFromImage(const T* params, const T* pixel, T* ray_in_cam) {
    return internal::NormalizeRay((pixel[0] - params[2]) / params[0],
                                  (pixel[1] - params[3]) / params[1], T(1),
                                  ray_in_cam);
  }

  static double PixelToAngle(const double* params) {
    return 2.0 / (params[0] + params[1]);
  }

  static std::string CheckParams(const std::vector<double>& params,
                                 int /*width*/, int /*height*/) {
    return internal::CheckCountFiniteFocal(kModelName, kParamsInfo,
                                           kNumParams, params);
  }
};

// Pinhole with radial-tangential distortion of (u, v) = (x / z, y / z):
//   du = u (k1 r² + k2 r⁴) + 2 p1 u v + p2 (r² + 2 u²)
//   dv = v (k1 r² + k2 r⁴) + 2 p2 u v + p1 (r² + 2 v²)
//   px = fx (u + du) + cx,  py = fy (v + dv) + cy.
struct OpenCVModel {
  static constexpr int kModelId = 4;
  static constexpr const char* kModelName = "OPENCV";
  static constexpr int kNumParams = 8;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, k1, k2, p1, p2";
  static constexpr std::array<int, 2> kFocalLengthIdxs = {0, 1};
  static constexpr std::array<int, 2> kPrincipalPointIdxs = {2, 3};
  static constexpr std::array<int, 4> kExtraParamsIdxs = {4, 5, 6, 7};
  static constexpr std::array<int, 0> kFixedParamsIdxs = {};

  static std::vector<double> InitialParams(double focal_length, int width,
                                           int height) {
    return {focal_length, focal_length, width / 2.0, height / 2.0,
            0.0,          0.0,          0.0,         0.0};
  }

  template <typename T>
  static bool ImageFromRay(const T* params, const T* ray_in_cam, T* pixel) {
    const T& z = ray_in_cam[2];
    if (z == T(0)) return false;
    T ud, vd;
    internal::DistortRadTan(params + 4, ray_in_cam[0] / z, ray_in_cam[1] / z,
                            &ud, &vd);
    pixel[0] = params[0] * ud + params[2];
    pixel[1] = params[1] * vd + params[3];
    return z > T(0);
  }

  // False where the Newton inversion of the distortion does not converge.
  template <typename T>
  static bool RayFromImage(const T* params, const T* pixel, T* ray_in_cam) {
    T u, v;
    if (!internal::UndistortRadTan(params + 4,
                                   (pixel[0] - params[2]) / params[0],
                                   (pixel[1] - params[3]) / params[1], &u,
                                   &v)) {
      return false;
    }
    return internal::NormalizeRay(u, v, T(1), ray_in_cam);
  }

  static double PixelToAngle(const double* params) {
    return 2.0 / (params[0] + params[1]);
  }

  static std::string CheckParams(const std::vector<double>& params,
                                 int /*width*/, int /*height*/) {
    return internal::CheckCountFiniteFocal(kModelName, kParamsInfo,
                                           kNumParams, params);
  }
};

}  // namespace sphera
