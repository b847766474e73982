// Kannala-Brandt fisheye models with upstream COLMAP's ids, names and
// parameter order, over the lens's whole field of view (beyond 180°):
//   OPENCV_FISHEYE, id 5:      fx, fy, cx, cy, k1, k2, k3, k4
//   THIN_PRISM_FISHEYE, id 10: fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1
//
// theta = atan2(sqrt(x² + y²), z) is the angle between the ray and +z.
// Upstream takes theta = atan(r) of the normalized point (x / z, y / z),
// r = |(x, y)| / z, which is the same angle for z > 0; upstream stops there.
// The ray is scaled onto the "theta plane":
//   (a, b) = theta (x, y) / sqrt(x² + y²),   |(a, b)| = theta.
// OPENCV_FISHEYE:
//   r(theta) = theta (1 + k1 theta² + k2 theta⁴ + k3 theta⁶ + k4 theta⁸)
//   px = fx (r(theta) / theta) a + cx,   py = fy (r(theta) / theta) b + cy.
// THIN_PRISM_FISHEYE (Weng et al. 1992; upstream applies it on the theta
// plane):
//   radial = k1 theta² + k2 theta⁴ + k3 theta⁶ + k4 theta⁸
//   ad = a + a radial + 2 p1 a b + p2 (theta² + 2 a²) + sx1 theta²
//   bd = b + b radial + 2 p2 a b + p1 (theta² + 2 b²) + sy1 theta²
//   px = fx ad + cx,   py = fy bd + cy.
//
// Field of view. The polynomial r(theta) is fitted to a lens over its image
// circle and is monotone only up to theta_max, the first theta in (0, pi]
// where dr/dtheta = 1 + 3 k1 theta² + 5 k2 theta⁴ + 7 k3 theta⁶ + 9 k4 theta⁸
// <= 0 (pi if there is none); beyond it the projection folds back onto pixels
// that nearer rays already own. A ray is visible iff theta < theta_max. The
// backward axis (theta = pi) is never visible: the whole circle r = r(pi) is
// its image. THIN_PRISM_FISHEYE takes theta_max from its radial terms (k1, k2,
// k3, k4) and in addition needs a positive Jacobian determinant of
// (a, b) -> (ad, bd) at the ray: its tangential and prism terms shift the fold
// locally. CheckParams refuses parameters whose fold lies inside the image
// circle (fold.h).
//
// Field in front of the image plane. When every pixel of the image circle the
// frame shows (common.h, FrameCircleRadius) sees a ray with theta < 90°
// (FieldInFrontOfImagePlane), the lens is one upstream's perspective models
// cover, and COLMAP treats it as upstream does
// (colmap_ext/scene/camera_category.h).
//
// Unprojection, m = ((px - cx) / fx, (py - cy) / fy): OPENCV_FISHEYE solves
// r(theta) = |m| on [0, theta_max) by safeguarded Newton; THIN_PRISM_FISHEYE
// inverts (a, b) -> (ad, bd) by Newton's method started from the radial
// solution. Then ray = (sin(theta) (a, b) / theta, cos(theta)).
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "camera_models/common.h"
#include "camera_models/fold.h"
#include "camera_models/polynomial.h"
#include "camera_models/recent_answers.h"

namespace sphera {
namespace internal {

// r(theta) / theta = 1 + k1 theta² + ... + k4 theta⁸, k = (k1, k2, k3, k4).
template <typename T>
T KannalaBrandtRadialFactor(const T* k, const T& theta2) {
  return T(1) +
         theta2 * (k[0] + theta2 * (k[1] + theta2 * (k[2] + theta2 * k[3])));
}

template <typename T>
T KannalaBrandtRadius(const T* k, const T& theta) {
  return theta * KannalaBrandtRadialFactor(k, theta * theta);
}

// dr / dtheta.
template <typename T>
T KannalaBrandtSlope(const T* k, const T& theta) {
  const T theta2 = theta * theta;
  return T(1) +
         theta2 * (T(3) * k[0] +
                   theta2 * (T(5) * k[1] +
                             theta2 * (T(7) * k[2] + theta2 * T(9) * k[3])));
}

struct KannalaBrandtField {
  double theta_max;  // a ray is visible iff theta < theta_max
  bool folds;        // dr/dtheta reaches 0 at theta_max (else theta_max = pi)
};

// theta_max of the radial coefficients k = (k1, k2, k3, k4): the first root of
// dr/dtheta, a quartic in theta², in (0, pi²]. NaN coefficients give
// theta_max = 0 (nothing visible). The last answers for a few lenses are
// kept per thread: the renderer and bundle adjustment ask with the same
// lenses for every pixel, and a rig's lenses alternate.
inline KannalaBrandtField KannalaBrandtFieldOfView(const double* k) {
  thread_local RecentAnswers<KannalaBrandtField, 8, 4> kept;
  return kept.Get(k, 4, [k] {
    const double slope_in_theta2[5] = {1, 3 * k[0], 5 * k[1], 7 * k[2],
                                       9 * k[3]};
    double theta2_fold;
    if (FirstNonPositive(slope_in_theta2, 5, 0.0, kPi * kPi, &theta2_fold)) {
      return KannalaBrandtField{std::sqrt(theta2_fold), true};
    }
    return KannalaBrandtField{kPi, false};
  });
}

// The theta-plane point (a, b) of a ray and the value of theta. Near the
// forward axis theta / rho = atan(rho / z) / rho = 1 / z - rho² / (3 z³) +
// O(rho⁴ / z⁵), which keeps ceres::Jet derivatives finite where sqrt(rho²)
// would not; the dropped term is below 1e-16 relative for rho² <= 1e-8 z².
// The backward axis gets (a, b) = (pi, 0), one point of its image circle.
// False only for the zero ray.
template <typename T>
bool ThetaPlaneFromRay(const T* ray_in_cam, T* a, T* b, double* theta_value) {
  using std::atan2;
  using std::sqrt;
  const T& x = ray_in_cam[0];
  const T& y = ray_in_cam[1];
  const T& z = ray_in_cam[2];
  const T rho2 = x * x + y * y;
  const double rho2_value = ScalarPart(rho2);
  const double z_value = ScalarPart(z);
  if (z_value > 0 && rho2_value <= 1e-8 * z_value * z_value) {
    const T inv_z = T(1) / z;
    const T theta_over_rho = inv_z - rho2 * inv_z * inv_z * inv_z / T(3);
    *a = theta_over_rho * x;
    *b = theta_over_rho * y;
    *theta_value = std::atan2(std::sqrt(rho2_value), z_value);
    return true;
  }
  if (!(rho2_value > 0)) {
    if (!(z_value < 0)) return false;
    *a = T(kPi);
    *b = T(0);
    *theta_value = kPi;
    return true;
  }
  const T rho = sqrt(rho2);
  const T theta = atan2(rho, z);
  *a = theta * x / rho;
  *b = theta * y / rho;
  *theta_value = ScalarPart(theta);
  return true;
}

// The unit ray of the theta-plane point (a, b):
// (sin(theta) / theta (a, b), cos(theta)), theta = |(a, b)|, with the Taylor
// series of sin(theta) / theta and cos(theta) in theta² near the axis (error
// below theta⁶ / 720 < 1e-26 for theta² < 1e-8), smooth for ceres::Jet.
template <typename T>
void RayFromThetaPlane(const T& a, const T& b, T* ray_in_cam) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta2 = a * a + b * b;
  T sin_over_theta, cos_theta;
  if (ScalarPart(theta2) < 1e-8) {
    sin_over_theta = T(1) - theta2 / T(6) + theta2 * theta2 / T(120);
    cos_theta = T(1) - theta2 / T(2) + theta2 * theta2 / T(24);
  } else {
    const T theta = sqrt(theta2);
    sin_over_theta = sin(theta) / theta;
    cos_theta = cos(theta);
  }
  ray_in_cam[0] = sin_over_theta * a;
  ray_in_cam[1] = sin_over_theta * b;
  ray_in_cam[2] = cos_theta;
}

// Upstream's THIN_PRISM_FISHEYE distortion of the theta-plane point (a, b),
// extra = (k1, k2, p1, p2, k3, k4, sx1, sy1): (ad, bd) and, if jacobian is not
// null, d(ad, bd) / d(a, b) row-major.
template <typename T>
void ThinPrismDistortion(const T* extra, const T& a, const T& b, T* ad, T* bd,
                         T* jacobian = nullptr) {
  const T& k1 = extra[0];
  const T& k2 = extra[1];
  const T& p1 = extra[2];
  const T& p2 = extra[3];
  const T& k3 = extra[4];
  const T& k4 = extra[5];
  const T& sx1 = extra[6];
  const T& sy1 = extra[7];
  const T a2 = a * a;
  const T b2 = b * b;
  const T ab = a * b;
  const T r2 = a2 + b2;
  const T radial = r2 * (k1 + r2 * (k2 + r2 * (k3 + r2 * k4)));
  *ad = a + a * radial + T(2) * p1 * ab + p2 * (r2 + T(2) * a2) + sx1 * r2;
  *bd = b + b * radial + T(2) * p2 * ab + p1 * (r2 + T(2) * b2) + sy1 * r2;
  if (jacobian != nullptr) {
    // d radial / d a = 2 a (k1 + 2 k2 r2 + 3 k3 r2² + 4 k4 r2³), same for b.
    const T dradial =
        T(2) * (k1 + r2 * (T(2) * k2 + r2 * (T(3) * k3 + r2 * T(4) * k4)));
    jacobian[0] = T(1) + radial + a2 * dradial + T(2) * p1 * b + T(6) * p2 * a +
                  T(2) * sx1 * a;
    jacobian[1] = ab * dradial + T(2) * p1 * a + T(2) * p2 * b + T(2) * sx1 * b;
    jacobian[2] = ab * dradial + T(2) * p2 * b + T(2) * p1 * a + T(2) * sy1 * a;
    jacobian[3] = T(1) + radial + b2 * dradial + T(2) * p2 * a + T(6) * p1 * b +
                  T(2) * sy1 * b;
  }
}

inline double ThinPrismJacobianDeterminant(const double* extra, double a,
                                           double b) {
  double ad, bd, jacobian[4];
  ThinPrismDistortion(extra, a, b, &ad, &bd, jacobian);
  return jacobian[0] * jacobian[3] - jacobian[1] * jacobian[2];
}

// theta in [0, theta_max) with r(theta) = radius; false if there is none.
inline bool KannalaBrandtThetaFromRadius(const double* k,
                                         const KannalaBrandtField& field,
                                         double radius, double* theta) {
  if (!(radius >= 0) || !(radius < KannalaBrandtRadius(k, field.theta_max))) {
    return false;
  }
  return SolveIncreasing(
      [k](double t, double* r, double* dr) {
        *r = KannalaBrandtRadius(k, t);
        *dr = KannalaBrandtSlope(k, t);
      },
      0.0, field.theta_max, radius, theta);
}

}  // namespace internal

struct OpenCVFisheyeModel {
  static constexpr int kModelId = 5;
  static constexpr const char* kModelName = "OPENCV_FISHEYE";
  static constexpr int kNumParams = 8;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, k1, k2, k3, k4";
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
    T a, b;
    double theta;
    if (!internal::ThetaPlaneFromRay(ray_in_cam, &a, &b, &theta)) return false;
    const T factor =
        internal::KannalaBrandtRadialFactor(params + 4, a * a + b * b);
    pixel[0] = params[0] * factor * a + params[2];
    pixel[1] = params[1] * factor * b + params[3];
    return theta < FieldOfView(params).theta_max;
  }

  template <typename T>
  static bool RayFromImage(const T* params, const T* pixel, T* ray_in_cam) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const T mx = (pixel[0] - params[2]) / params[0];
    const T my = (pixel[1] - params[3]) / params[1];
    const T radius2 = mx * mx + my * my;
    const double k[4] = {
        internal::ScalarPart(params[4]), internal::ScalarPart(params[5]),
        internal::ScalarPart(params[6]), internal::ScalarPart(params[7])};
    double theta_value;
    if (!internal::KannalaBrandtThetaFromRadius(
            k, FieldOfView(params), std::sqrt(internal::ScalarPart(radius2)),
            &theta_value)) {
      return false;
    }
    if (theta_value < 1e-6) {
      // theta = |m| - k1 |m|³ + O(|m|⁵), so sin(theta) / |m| = 1 - (k1 + 1/6)
      // |m|² and cos(theta) = 1 - |m|² / 2, up to O(|m|⁴) < 1e-23; smooth in
      // m where |m| = sqrt(radius2) is not (ceres::Jet at the centre).
      const T sin_over_radius = T(1) - (params[4] + T(1.0 / 6.0)) * radius2;
      ray_in_cam[0] = sin_over_radius * mx;
      ray_in_cam[1] = sin_over_radius * my;
      ray_in_cam[2] = T(1) - radius2 / T(2);
      return true;
    }
    // The root is found on values; one Newton step in T from it leaves the
    // value and gives the derivative parts of a ceres::Jet the
    // implicit-function derivative.
    const T radius = sqrt(radius2);
    const T theta0(theta_value);
    const T theta =
        theta0 - (internal::KannalaBrandtRadius(params + 4, theta0) - radius) /
                     internal::KannalaBrandtSlope(params + 4, theta0);
    const T sin_over_radius = sin(theta) / radius;
    ray_in_cam[0] = sin_over_radius * mx;
    ray_in_cam[1] = sin_over_radius * my;
    ray_in_cam[2] = cos(theta);
    return true;
  }

  // Near the axis r(theta) ~ theta.
  static double PixelToAngle(const double* params) {
    return 2.0 / (params[0] + params[1]);
  }

  // theta_max of the parameters' values.
  template <typename T>
  static internal::KannalaBrandtField FieldOfView(const T* params) {
    const double k[4] = {
        internal::ScalarPart(params[4]), internal::ScalarPart(params[5]),
        internal::ScalarPart(params[6]), internal::ScalarPart(params[7])};
    return internal::KannalaBrandtFieldOfView(k);
  }

  // Whether every pixel of the image circle a width x height frame shows
  // sees a ray with theta < 90° (or none, beyond a fold before 90°):
  // |m| = r(theta) is monotone below theta_max.
  static bool FieldInFrontOfImagePlane(const double* params, int width,
                                       int height) {
    if (width <= 0 || height <= 0) return false;
    constexpr double kHalfPi = internal::kPi / 2;
    if (FieldOfView(params).theta_max <= kHalfPi) return true;
    return internal::FrameCircleRadius(params, width, height) <
           internal::KannalaBrandtRadius(params + 4, kHalfPi);
  }

  static std::string CheckParams(const std::vector<double>& params, int width,
                                 int height) {
    using namespace internal;
    if (auto e =
            CheckCountFiniteFocal(kModelName, kParamsInfo, kNumParams, params);
        !e.empty())
      return e;
    const KannalaBrandtField field = FieldOfView(params.data());
    if (!field.folds) return "";
    const double fx = params[0], fy = params[1];
    return FoldInsideImageMessage(
        kModelName, field.theta_max,
        KannalaBrandtRadius(params.data() + 4, field.theta_max), params[2],
        params[3], width, height, [fx, fy](double dx, double dy) {
          return std::hypot(dx / fx, dy / fy);
        });
  }
};

struct ThinPrismFisheyeModel {
  static constexpr int kModelId = 10;
  static constexpr const char* kModelName = "THIN_PRISM_FISHEYE";
  static constexpr int kNumParams = 12;
  static constexpr const char* kParamsInfo =
      "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1";
  static constexpr std::array<int, 2> kFocalLengthIdxs = {0, 1};
  static constexpr std::array<int, 2> kPrincipalPointIdxs = {2, 3};
  static constexpr std::array<int, 8> kExtraParamsIdxs = {4, 5, 6,  7,
                                                          8, 9, 10, 11};
  static constexpr std::array<int, 0> kFixedParamsIdxs = {};

  static std::vector<double> InitialParams(double focal_length, int width,
                                           int height) {
    return {focal_length,
            focal_length,
            width / 2.0,
            height / 2.0,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            0};
  }

  template <typename T>
  static bool ImageFromRay(const T* params, const T* ray_in_cam, T* pixel) {
    T a, b;
    double theta;
    if (!internal::ThetaPlaneFromRay(ray_in_cam, &a, &b, &theta)) return false;
    T ad, bd;
    internal::ThinPrismDistortion(params + 4, a, b, &ad, &bd);
    pixel[0] = params[0] * ad + params[2];
    pixel[1] = params[1] * bd + params[3];
    double extra[8];
    for (int i = 0; i < 8; ++i) extra[i] = internal::ScalarPart(params[4 + i]);
    return theta < FieldOfView(params).theta_max &&
           internal::ThinPrismJacobianDeterminant(
               extra, internal::ScalarPart(a), internal::ScalarPart(b)) > 0;
  }

  // False where Newton's method does not converge to a visible point.
  template <typename T>
  static bool RayFromImage(const T* params, const T* pixel, T* ray_in_cam) {
    const T mdx = (pixel[0] - params[2]) / params[0];
    const T mdy = (pixel[1] - params[3]) / params[1];
    double extra[8];
    for (int i = 0; i < 8; ++i) extra[i] = internal::ScalarPart(params[4 + i]);
    double a_value, b_value;
    if (!UndistortScalar(extra, FieldOfView(params), internal::ScalarPart(mdx),
                         internal::ScalarPart(mdy), &a_value, &b_value)) {
      return false;
    }
    // One Newton step in T from the root: the value stays, ceres::Jet
    // derivative parts become the implicit-function derivative.
    const T a0(a_value);
    const T b0(b_value);
    T ad, bd, jacobian[4];
    internal::ThinPrismDistortion(params + 4, a0, b0, &ad, &bd, jacobian);
    const T det = jacobian[0] * jacobian[3] - jacobian[1] * jacobian[2];
    const T res_a = ad - mdx;
    const T res_b = bd - mdy;
    const T a = a0 - (jacobian[3] * res_a - jacobian[1] * res_b) / det;
    const T b = b0 - (jacobian[0] * res_b - jacobian[2] * res_a) / det;
    internal::RayFromThetaPlane(a, b, ray_in_cam);
    return true;
  }

  static double PixelToAngle(const double* params) {
    return 2.0 / (params[0] + params[1]);
  }

  // theta_max of the radial terms (k1, k2, k3, k4) of the parameters' values.
  template <typename T>
  static internal::KannalaBrandtField FieldOfView(const T* params) {
    const double k[4] = {
        internal::ScalarPart(params[4]), internal::ScalarPart(params[5]),
        internal::ScalarPart(params[8]), internal::ScalarPart(params[9])};
    return internal::KannalaBrandtFieldOfView(k);
  }

  // Whether every pixel of the image circle a width x height frame shows
  // sees a ray with theta < 90° (or none, beyond a fold before 90°). The
  // tangential and prism terms are a small smooth shift of the radial map:
  // the rays of the circle's rim in 16 directions decide.
  static bool FieldInFrontOfImagePlane(const double* params, int width,
                                       int height) {
    if (width <= 0 || height <= 0) return false;
    const bool folds_in_front =
        FieldOfView(params).theta_max <= internal::kPi / 2;
    const double radius = internal::FrameCircleRadius(params, width, height);
    for (int i = 0; i < 16; ++i) {
      const double phi = i * internal::kPi / 8;
      const double pixel[2] = {params[2] + params[0] * radius * std::cos(phi),
                               params[3] + params[1] * radius * std::sin(phi)};
      double ray[3];
      if (RayFromImage(params, pixel, ray) ? ray[2] <= 0 : !folds_in_front) {
        return false;
      }
    }
    return true;
  }

  // Newton's method on (a, b) -> (ad, bd) from the radial-only solution; a
  // step that would leave theta < theta_max is halved. True if it converges
  // to a visible point (theta < theta_max, positive Jacobian determinant).
  static bool UndistortScalar(const double* extra,
                              const internal::KannalaBrandtField& field,
                              double mdx, double mdy, double* a, double* b) {
    using namespace internal;
    const double radius = std::hypot(mdx, mdy);
    if (!std::isfinite(radius)) return false;
    const double k[4] = {extra[0], extra[1], extra[4], extra[5]};
    double theta;
    if (!KannalaBrandtThetaFromRadius(k, field, radius, &theta)) {
      theta = 0.999 * field.theta_max;
    }
    double cur_a = radius > 0 ? theta * mdx / radius : 0.0;
    double cur_b = radius > 0 ? theta * mdy / radius : 0.0;
    const double theta_max2 = field.theta_max * field.theta_max;
    bool converged = false;
    for (int i = 0; i < 100 && !converged; ++i) {
      double ad, bd, jacobian[4];
      ThinPrismDistortion(extra, cur_a, cur_b, &ad, &bd, jacobian);
      const double det = jacobian[0] * jacobian[3] - jacobian[1] * jacobian[2];
      if (!(det != 0) || !std::isfinite(det)) return false;
      const double res_a = ad - mdx, res_b = bd - mdy;
      double step_a = (jacobian[3] * res_a - jacobian[1] * res_b) / det;
      double step_b = (jacobian[0] * res_b - jacobian[2] * res_a) / det;
      for (int halving = 0; halving < 60; ++halving) {
        const double next_a = cur_a - step_a, next_b = cur_b - step_b;
        if (next_a * next_a + next_b * next_b < theta_max2) break;
        step_a *= 0.5;
        step_b *= 0.5;
      }
      cur_a -= step_a;
      cur_b -= step_b;
      const double step2 = step_a * step_a + step_b * step_b;
      const double norm2 = cur_a * cur_a + cur_b * cur_b;
      if (!std::isfinite(norm2)) return false;
      converged = step2 <= 1e-30 * std::max(1.0, norm2);
    }
    double ad, bd;
    ThinPrismDistortion(extra, cur_a, cur_b, &ad, &bd);
    if (!(std::hypot(ad - mdx, bd - mdy) <= 1e-12 * (1.0 + radius))) {
      return false;
    }
    if (!(std::hypot(cur_a, cur_b) < field.theta_max) ||
        !(ThinPrismJacobianDeterminant(extra, cur_a, cur_b) > 0)) {
      return false;
    }
    *a = cur_a;
    *b = cur_b;
    return true;
  }

  // Refuses a fold inside the image circle (ImageCircleRadius). The visible
  // region ends, along each of 360 meridians of the theta plane, at the
  // first theta where the Jacobian determinant of the distortion reaches 0
  // (located on 512 steps, then bisected) or at the radial fold theta_max; a
  // fold is inside the image circle when that boundary point's pixel is.
  static std::string CheckParams(const std::vector<double>& params, int width,
                                 int height) {
    using namespace internal;
    if (auto e =
            CheckCountFiniteFocal(kModelName, kParamsInfo, kNumParams, params);
        !e.empty())
      return e;
    if (width <= 0 || height <= 0) return "";
    const KannalaBrandtField field = FieldOfView(params.data());
    const double* extra = params.data() + 4;
    const double circle_px =
        ImageCircleRadius(params[2], params[3], width, height);
    constexpr int kMeridians = 360;
    constexpr int kSteps = 512;
    double best_theta = std::numeric_limits<double>::infinity();
    double best_x = 0, best_y = 0;
    for (int j = 0; j < kMeridians; ++j) {
      const double phi = 2 * kPi * j / kMeridians;
      const double dir_a = std::cos(phi), dir_b = std::sin(phi);
      auto det_at = [&](double theta) {
        return ThinPrismJacobianDeterminant(extra, theta * dir_a,
                                            theta * dir_b);
      };
      double boundary = -1;
      for (int i = 1; i <= kSteps && boundary < 0; ++i) {
        double hi = field.theta_max * i / kSteps;
        if (det_at(hi) > 0) continue;
        double lo = field.theta_max * (i - 1) / kSteps;
        for (int k = 0; k < 60; ++k) {
          const double mid = 0.5 * (lo + hi);
          (det_at(mid) > 0 ? lo : hi) = mid;
        }
        boundary = hi;
      }
      if (boundary < 0 && field.folds) boundary = field.theta_max;
      if (boundary < 0 || !(boundary < best_theta)) continue;
      double ad, bd;
      ThinPrismDistortion(extra, boundary * dir_a, boundary * dir_b, &ad, &bd);
      const double x = params[0] * ad + params[2];
      const double y = params[1] * bd + params[3];
      if (std::hypot(x - params[2], y - params[3]) <= circle_px) {
        best_theta = boundary;
        best_x = x;
        best_y = y;
      }
    }
    if (!std::isfinite(best_theta)) return "";
    return FoldMessage(kModelName, best_theta,
                       std::hypot(best_x - params[2], best_y - params[3]),
                       params[2], params[3], width, height,
                       ": at pixel (" + FormatFixed(best_x, 1) + ", " +
                           FormatFixed(best_y, 1) + ")");
  }
};

}  // namespace sphera
