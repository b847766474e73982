// Scaramuzza's omnidirectional camera model as OCamCalib calibrates it
// (Scaramuzza, Martinelli, Siegwart 2006), id 66:
//   cx, cy, c, d, e, a0, a2, a3, a4
//
// A pixel (px, py), px along the columns and py along the rows, lifts to the
// sensor point s through OCamCalib's affine map, which works in (row, column)
// order:
//   [py - cy; px - cx] = [[c, d], [e, 1]] [s_row; s_col],
// and its ray is
//   ray_in_cam = normalize(s_col, s_row, -f(rho)),  rho = |s|,
//   f(rho) = a0 + a2 rho² + a3 rho³ + a4 rho⁴   (a1 = 0, as OCamCalib fits it).
// Convention: +z is the optical axis, x right, y down, as in every model of
// this library. OCamCalib's camera frame has x along the rows, y along the
// columns and z = x × y pointing back out of the lens, which is why its
// polynomial is negative on the axis (a0 < 0) and why the ray here takes -f.
// The numbers of OCamCalib's calib_results.txt carry over unchanged: its xc
// (a row) is cy, its yc (a column) is cx, c, d, e are the same, and
// pol = (a0, 0, a2, a3, a4). Its inverse polynomial is not used: projection
// solves f exactly.
//
// Field of view. The ray at sensor radius rho is at theta(rho) =
// atan2(rho, -f(rho)) from +z, and d theta / d rho = m(rho) / (rho² + f²) with
//   m(rho) = -f + rho f' = -a0 + a2 rho² + 2 a3 rho³ + 3 a4 rho⁴.
// The projection is monotone up to rho_max, the first positive root of m: the
// largest image circle the polynomial describes (beyond it the fitted
// polynomial folds and two rays share a pixel). Without a root theta grows to
// pi as rho grows (to pi / 2 when a2 = a3 = a4 = 0, a pinhole of focal -a0).
// A pixel is in the domain iff rho < rho_max; a ray is visible iff
// theta < theta_max = theta(rho_max) (pi, resp. pi / 2, without a fold). The
// backward axis is never visible.
//
// Projection: s = q (x, y), where q > 0 solves
//   E(q) = q z + f(q sqrt(x² + y²)) = 0,
// which says that (s, -f(|s|)) is parallel to the ray. E(q) is proportional to
// |(rho, -f)| sin(theta(rho) - theta_ray), so on [0, rho_max) it changes sign
// exactly once, at the ray; it is solved by safeguarded Newton. Near the axis
// q -> -a0 / z, so E stays regular there.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "camera_models/common.h"
#include "camera_models/fold.h"
#include "camera_models/polynomial.h"

namespace sphera {
namespace internal {

struct OCamField {
  double rho_max;    // sensor radius where the projection folds (inf: never)
  double theta_max;  // a ray is visible iff its angle from +z is below this
  bool folds;
};

// f(rho) = a0 + a2 rho² + a3 rho³ + a4 rho⁴, poly = (a0, a2, a3, a4).
template <typename T>
T OCamPolynomial(const T* poly, const T& rho) {
  const T rho2 = rho * rho;
  return poly[0] + rho2 * (poly[1] + rho * (poly[2] + rho * poly[3]));
}

// The field of poly = (a0, a2, a3, a4). m(rho) has its roots inside the
// Cauchy bound 1 + max |m_i / m_lead|. a0 >= 0 or NaN gives rho_max = 0
// (nothing visible). The last answer is kept per thread: the renderer and
// bundle adjustment ask with the same lens for every pixel.
inline OCamField OCamFieldOfView(const double* poly) {
  thread_local std::array<double, 4> cached_poly = {
      std::numeric_limits<double>::quiet_NaN(), 0, 0, 0};
  thread_local OCamField cached = {0, 0, true};
  if (poly[0] == cached_poly[0] && poly[1] == cached_poly[1] &&
      poly[2] == cached_poly[2] && poly[3] == cached_poly[3]) {
    return cached;
  }
  const double m[5] = {-poly[0], 0, poly[1], 2 * poly[2], 3 * poly[3]};
  int lead = 4;
  while (lead > 0 && m[lead] == 0) --lead;
  double bound = 1;
  for (int i = 0; i < lead; ++i) {
    bound = std::max(bound, 1 + std::abs(m[i] / m[lead]));
  }
  OCamField field;
  double rho_fold;
  if (FirstNonPositive(m, 5, 0.0, bound, &rho_fold)) {
    field = {rho_fold, std::atan2(rho_fold, -OCamPolynomial(poly, rho_fold)),
             true};
  } else {
    const bool pinhole = poly[1] == 0 && poly[2] == 0 && poly[3] == 0;
    field = {std::numeric_limits<double>::infinity(), pinhole ? kPi / 2 : kPi,
             false};
  }
  cached_poly = {poly[0], poly[1], poly[2], poly[3]};
  cached = field;
  return field;
}

}  // namespace internal

struct OCamModel {
  static constexpr int kModelId = 66;
  static constexpr const char* kModelName = "OCAM";
  static constexpr int kNumParams = 9;
  static constexpr const char* kParamsInfo = "cx, cy, c, d, e, a0, a2, a3, a4";
  // No focal length: -a0 plays its part near the axis, but a change of scale
  // moves every coefficient (a_i -> a_i s^(1 - i)).
  static constexpr std::array<int, 0> kFocalLengthIdxs = {};
  static constexpr std::array<int, 2> kPrincipalPointIdxs = {0, 1};
  static constexpr std::array<int, 7> kExtraParamsIdxs = {2, 3, 4, 5, 6, 7, 8};
  static constexpr std::array<int, 0> kFixedParamsIdxs = {};

  // A pinhole of the given focal length (f = -focal_length).
  static std::vector<double> InitialParams(double focal_length, int width,
                                           int height) {
    return {width / 2.0, height / 2.0, 1, 0, 0, -focal_length, 0, 0, 0};
  }

  template <typename T>
  static bool ImageFromRay(const T* params, const T* ray_in_cam, T* pixel) {
    using std::sqrt;
    const T& x = ray_in_cam[0];
    const T& y = ray_in_cam[1];
    const T& z = ray_in_cam[2];
    const T* poly = params + 5;
    const double poly_value[4] = {
        internal::ScalarPart(poly[0]), internal::ScalarPart(poly[1]),
        internal::ScalarPart(poly[2]), internal::ScalarPart(poly[3])};
    const internal::OCamField field = internal::OCamFieldOfView(poly_value);
    const T rho_xy2 = x * x + y * y;
    const double rho_xy_value = std::sqrt(internal::ScalarPart(rho_xy2));
    const double z_value = internal::ScalarPart(z);
    if (!(rho_xy_value > 0) && !(z_value > 0)) return false;

    // E(q) = q z + f(q rho_xy) and dE/dq, on values.
    auto evaluate = [&](double q, double* e, double* de) {
      const double rho = q * rho_xy_value;
      *e = q * z_value + internal::OCamPolynomial(poly_value, rho);
      *de = z_value +
            rho_xy_value *
                (rho * (2 * poly_value[1] +
                        rho * (3 * poly_value[2] + rho * 4 * poly_value[3])));
    };
    double q_value;
    if (!(rho_xy_value > 0)) {
      q_value = -poly_value[0] / z_value;  // on the axis, rho = 0
      if (!(field.rho_max > 0)) return false;
    } else {
      double q_hi;
      if (field.folds) {
        q_hi = field.rho_max / rho_xy_value;
      } else {
        // theta(rho) -> theta_max without a fold: E turns positive at some
        // finite q for every visible ray.
        q_hi = std::max(1.0, -poly_value[0]) / rho_xy_value;
        for (int i = 0; i < 2000; ++i) {
          double e, de;
          evaluate(q_hi, &e, &de);
          if (e > 0 || !std::isfinite(e)) break;
          q_hi *= 2;
        }
      }
      double e_hi, de_hi;
      evaluate(q_hi, &e_hi, &de_hi);
      if (!(e_hi > 0) || !std::isfinite(q_hi)) return false;
      if (!internal::SolveIncreasing(evaluate, 0.0, q_hi, 0.0, &q_value)) {
        return false;
      }
    }

    // One Newton step on E in T from the root: the value stays, ceres::Jet
    // derivative parts become the implicit-function derivative. rho_xy³ is
    // rho_xy² rho_xy with rho_xy = 0 (not sqrt(0)) on the axis, where its
    // derivative vanishes.
    const T rho_xy = rho_xy_value > 0 ? sqrt(rho_xy2) : T(0);
    const T q0(q_value);
    const T rho = q0 * rho_xy;
    const T e = q0 * z + internal::OCamPolynomial(poly, rho);
    const T de =
        z + rho_xy * (rho * (T(2) * poly[1] +
                             rho * (T(3) * poly[2] + rho * T(4) * poly[3])));
    const T q = q0 - e / de;
    const T s_col = q * x;
    const T s_row = q * y;
    pixel[0] = params[4] * s_row + s_col + params[0];
    pixel[1] = params[2] * s_row + params[3] * s_col + params[1];
    return true;
  }

  template <typename T>
  static bool RayFromImage(const T* params, const T* pixel, T* ray_in_cam) {
    using std::sqrt;
    const T& c = params[2];
    const T& d = params[3];
    const T& e = params[4];
    const T* poly = params + 5;
    const T d_col = pixel[0] - params[0];
    const T d_row = pixel[1] - params[1];
    const T det = c - d * e;
    const T s_row = (d_row - d * d_col) / det;
    const T s_col = (c * d_col - e * d_row) / det;
    const T rho2 = s_row * s_row + s_col * s_col;
    const double rho_value = std::sqrt(internal::ScalarPart(rho2));
    const double poly_value[4] = {
        internal::ScalarPart(poly[0]), internal::ScalarPart(poly[1]),
        internal::ScalarPart(poly[2]), internal::ScalarPart(poly[3])};
    if (!(rho_value < internal::OCamFieldOfView(poly_value).rho_max)) {
      return false;
    }
    // rho³ = rho² rho with rho = 0 (not sqrt(0)) at the centre, where its
    // derivative vanishes.
    const T rho = rho_value > 0 ? sqrt(rho2) : T(0);
    return internal::NormalizeRay(
        s_col, s_row, -internal::OCamPolynomial(poly, rho), ray_in_cam);
  }

  // Near the axis theta ~ rho / -a0, and the affine map scales areas by
  // c - d e.
  static double PixelToAngle(const double* params) {
    return 1.0 / (std::abs(params[5]) *
                  std::sqrt(std::abs(params[2] - params[3] * params[4])));
  }

  // The parameters of the same lens in an image scaled by (scale_x,
  // scale_y): pixel' = (scale_x px, scale_y py). The sensor frame scales by
  // k = scale_x (the affine map keeps its 1), so f'(k rho) = k f(rho), i.e.
  // a_i -> a_i k^(1 - i), and c, d take the aspect change scale_y / scale_x.
  static void Rescale(double scale_x, double scale_y, double* params) {
    const double k = scale_x;
    params[0] *= scale_x;
    params[1] *= scale_y;
    params[2] *= scale_y / scale_x;
    params[3] *= scale_y / scale_x;
    params[5] *= k;
    params[6] /= k;
    params[7] /= k * k;
    params[8] /= k * k * k;
  }

  template <typename T>
  static internal::OCamField FieldOfView(const T* params) {
    const double poly[4] = {
        internal::ScalarPart(params[5]), internal::ScalarPart(params[6]),
        internal::ScalarPart(params[7]), internal::ScalarPart(params[8])};
    return internal::OCamFieldOfView(poly);
  }

  static std::string CheckParams(const std::vector<double>& params, int width,
                                 int height) {
    using namespace internal;
    if (auto e =
            CheckParamCount(kModelName, kParamsInfo, kNumParams, params.size());
        !e.empty())
      return e;
    if (auto e = CheckAllFinite(kModelName, kParamsInfo, params); !e.empty())
      return e;
    if (!(params[5] < 0)) {
      return std::string(kModelName) + ": a0=" + FormatNumber(params[5]) +
             " must be negative (f(0) = a0 on the optical axis, OCamCalib's "
             "sign)";
    }
    const double c = params[2], d = params[3], e = params[4];
    const double det = c - d * e;
    if (!(det > 0)) {
      return std::string(kModelName) + ": c - d e = " + FormatNumber(det) +
             " (c=" + FormatNumber(c) + ", d=" + FormatNumber(d) +
             ", e=" + FormatNumber(e) + ") must be positive";
    }
    const OCamField field = FieldOfView(params.data());
    if (!field.folds) return "";
    return FoldInsideImageMessage(
        kModelName, field.theta_max, field.rho_max, params[0], params[1], width,
        height, [c, d, e, det](double d_col, double d_row) {
          return std::hypot((d_row - d * d_col) / det,
                            (c * d_col - e * d_row) / det);
        });
  }
};

}  // namespace sphera
