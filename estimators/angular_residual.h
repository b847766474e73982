// SPHERA estimators: the angular (log-map) residual on the unit sphere.
//
// Mathematics
// -----------
// A central camera observes a 3D point through a unit bearing ray u in S^2.
// A model predicts a ray v = R X + t (camera frame, not necessarily unit).
// The natural error is the geodesic angle between u and v/|v|.  To give a
// least-squares solver a 2-vector whose squared norm is that angle squared, we
// use the logarithm map of S^2 at u, expressed in a tangent basis (e1, e2) of
// u (e1, e2, u orthonormal):
//
//   v^ = v / |v|,   c = u . v^,   w = v^ - c u   (tangent component),
//   a = e1 . v^ = e1 . w,   b = e2 . v^ = e2 . w,   s = |w| = sqrt(a^2 + b^2),
//   theta = atan2(s, c)                          (geodesic angle, in [0, pi]),
//   r = theta * (a, b) / s  =  Log_u(v^) in the basis (e1, e2).
//
// Hence |r| = theta exactly.  Because atan2(s, c) and (a, b)/s are invariant
// under a positive scaling of v, the normalisation of v is never performed:
// a, b, c are computed from the raw v.  acos is never used (and never
// differentiated), so the residual is accurate for tiny and large angles.
//
// Small-angle limit: with x = s / c (c > 0),
//   theta / s = atan(x) / (x c) = (1/c) (1 - x^2/3 + x^4/5 - x^6/7 + ...),
// which only involves x^2 = (a^2 + b^2) / c^2, i.e. no square root.  Using
// this series for x^2 < 1e-4 keeps ceres::Jet derivatives finite at zero error
// (sqrt has an infinite derivative at 0); the truncation error is
// O(x^8) < 1e-16 relative.
//
// The residual is singular only at the antipode (v^ = -u, theta = pi) where
// the direction of the log map is undefined; we return (pi, 0) there.
//
// Tangent basis: the branchless orthonormal basis of Duff et al., "Building an
// Orthonormal Basis, Revisited" (JCGT 2017): with sigma = sign(u_z) and
// k = -1 / (sigma + u_z),
//   e1 = (1 + sigma k u_x^2, sigma k u_x u_y, -sigma u_x),
//   e2 = (k u_x u_y, sigma + k u_y^2, -u_y),
// which is deterministic, smooth away from the plane u_z = 0 (where sigma
// flips), and satisfies e1 x e2 = u.  Requires |u| = 1.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include "camera_models/common.h"

namespace sphera {

// Tangent basis (e1, e2) of the unit vector u, see header comment.
template <typename T>
inline void RayTangentBasis(const T* u, T* e1, T* e2) {
  const T sigma = (u[2] < T(0)) ? T(-1) : T(1);
  const T k = T(-1) / (sigma + u[2]);
  const T kxy = k * u[0] * u[1];
  e1[0] = T(1) + sigma * k * u[0] * u[0];
  e1[1] = sigma * kxy;
  e1[2] = -sigma * u[0];
  e2[0] = kxy;
  e2[1] = sigma + k * u[1] * u[1];
  e2[2] = -u[1];
}

inline void RayTangentBasis(const Eigen::Vector3d& u, Eigen::Vector3d* e1,
                            Eigen::Vector3d* e2) {
  RayTangentBasis(u.data(), e1->data(), e2->data());
}

// Log-map residual from the tangent/normal components of the predicted ray:
// a = e1 . v, b = e2 . v, c = u . v (v need not be unit).  See header.
template <typename T>
inline void LogMapResidualFromComponents(const T& a, const T& b, const T& c,
                                         T* residual) {
  const T s2 = a * a + b * b;
  if (c > T(0) && s2 < T(1e-4) * c * c) {
    // theta / s = (1/c)(1 - x^2/3 + x^4/5 - x^6/7), x^2 = s^2 / c^2.
    const T x2 = s2 / (c * c);
    const T scale =
        (T(1) - x2 * (T(1.0 / 3.0) - x2 * (T(1.0 / 5.0) - x2 * T(1.0 / 7.0)))) /
        c;
    residual[0] = scale * a;
    residual[1] = scale * b;
    return;
  }
  if (s2 == T(0)) {
    // v^ = -u (antipode) or v = 0: direction undefined, angle = pi.
    residual[0] = T(M_PI);
    residual[1] = T(0);
    return;
  }
  using std::atan2;
  using std::sqrt;
  const T s = sqrt(s2);
  const T scale = atan2(s, c) / s;
  residual[0] = scale * a;
  residual[1] = scale * b;
}

// Log-map residual of the predicted ray v at the observed unit ray u, with the
// tangent basis of u computed internally (templated, Jet-safe).
template <typename T>
inline void AngularLogResidual(const T* u, const T* v, T* residual) {
  T e1[3], e2[3];
  RayTangentBasis(u, e1, e2);
  const T a = e1[0] * v[0] + e1[1] * v[1] + e1[2] * v[2];
  const T b = e2[0] * v[0] + e2[1] * v[1] + e2[2] * v[2];
  const T c = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
  LogMapResidualFromComponents(a, b, c, residual);
}

// The same residual in doubles with its analytic Jacobian dr/dv (2 x 3,
// row-major; nullptr skips it), u fixed.  With g = theta / s and
// n2 = s^2 + c^2 = |v|^2:
//
//   dr/d(a, b, c) = [g + a^2 h,  a b h,      -a / n2]
//                   [a b h,      g + b^2 h,  -b / n2],
//   h = (c / n2 - g) / s^2,   dr/dv = dr/d(a, b, c) [e1; e2; u].
//
// h stays finite at s = 0: for x^2 = s^2 / c^2 < 1e-4 (c > 0) it is the
// series (1 / c^3) sum_{k>=1} (-1)^k 2k / (2k + 1) x^(2k - 2), truncated
// after x^6 like g itself.  At the antipode (s = 0, c <= 0) the residual is
// (pi, 0) and the Jacobian zero, as the templated version gives.
inline void AngularLogResidualWithJacobian(const double* u, const double* v,
                                           double* residual,
                                           double* dresidual_dv) {
  double e1[3], e2[3];
  RayTangentBasis(u, e1, e2);
  const double a = e1[0] * v[0] + e1[1] * v[1] + e1[2] * v[2];
  const double b = e2[0] * v[0] + e2[1] * v[1] + e2[2] * v[2];
  const double c = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
  const double s2 = a * a + b * b;
  double g, h;
  if (c > 0 && s2 < 1e-4 * c * c) {
    const double x2 = s2 / (c * c);
    g = (1 - x2 * (1.0 / 3.0 - x2 * (1.0 / 5.0 - x2 * (1.0 / 7.0)))) / c;
    h = (-2.0 / 3.0 + x2 * (4.0 / 5.0 - x2 * (6.0 / 7.0 - x2 * (8.0 / 9.0)))) /
        (c * c * c);
  } else if (s2 == 0) {
    residual[0] = M_PI;
    residual[1] = 0;
    if (dresidual_dv != nullptr) {
      std::fill(dresidual_dv, dresidual_dv + 6, 0.0);
    }
    return;
  } else {
    const double s = std::sqrt(s2);
    g = std::atan2(s, c) / s;
    h = (c / (s2 + c * c) - g) / s2;
  }
  residual[0] = g * a;
  residual[1] = g * b;
  if (dresidual_dv == nullptr) {
    return;
  }
  const double n2 = s2 + c * c;
  const double d[2][3] = {{g + a * a * h, a * b * h, -a / n2},
                          {a * b * h, g + b * b * h, -b / n2}};
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 3; ++col) {
      dresidual_dv[3 * row + col] =
          d[row][0] * e1[col] + d[row][1] * e2[col] + d[row][2] * u[col];
    }
  }
}

// Geodesic angle between two (not necessarily unit) directions, in [0, pi]:
// theta = atan2(|a x b|, a . b).  Accurate at 0 and pi (no acos).
inline double AngleBetweenRays(const Eigen::Vector3d& a,
                               const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// Same residual with a fixed camera (cam_from_world = [R | t]); only the
// point X (3) is a parameter.  Used for triangulation refinement.
class AngularReprojectionConstantPoseCost {
 public:
  AngularReprojectionConstantPoseCost(const Eigen::Vector3d& observed_ray,
                                      const Eigen::Matrix3d& cam_from_world_R,
                                      const Eigen::Vector3d& cam_from_world_t)
      : u_(observed_ray.normalized()) {
    Eigen::Vector3d e1, e2;
    RayTangentBasis(u_, &e1, &e2);
    // Rows: e1, e2, u applied to (R X + t) -> a, b, c are affine in X.
    Eigen::Matrix3d B;
    B.row(0) = e1.transpose();
    B.row(1) = e2.transpose();
    B.row(2) = u_.transpose();
    A_ = B * cam_from_world_R;
    b_ = B * cam_from_world_t;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& observed_ray,
                                     const Eigen::Matrix3d& cam_from_world_R,
                                     const Eigen::Vector3d& cam_from_world_t) {
    return new ceres::AutoDiffCostFunction<AngularReprojectionConstantPoseCost,
                                           2, 3>(
        new AngularReprojectionConstantPoseCost(observed_ray, cam_from_world_R,
                                                cam_from_world_t));
  }

  template <typename T>
  bool operator()(const T* const point3D, T* residuals) const {
    T abc[3];
    for (int i = 0; i < 3; ++i) {
      abc[i] = T(A_(i, 0)) * point3D[0] + T(A_(i, 1)) * point3D[1] +
               T(A_(i, 2)) * point3D[2] + T(b_(i));
    }
    LogMapResidualFromComponents(abc[0], abc[1], abc[2], residuals);
    return true;
  }

 private:
  Eigen::Vector3d u_;
  Eigen::Matrix3d A_;
  Eigen::Vector3d b_;
};

// Model::RayFromImage (a camera_models/ model), succeeding wherever the lift
// of the scalar parts succeeds. In Jets a model's arithmetic rounds
// differently (ceres::Jet divides by multiplying with the reciprocal), so at
// the edge of its domain (where radial distortion folds, or Newton's
// iteration stops converging) the Jet lift can fail on a pixel whose lift in
// doubles succeeds. Ceres asks for derivatives only where it has evaluated
// the cost, and a failure there ends the whole solve; so where only the Jet
// lift fails, the ray of the scalar parts is returned without derivatives
// by the parameters.
template <typename Model, typename T>
bool RayFromImageOrScalarRay(const T* params, const T* pixel, T* ray_in_cam) {
  if (Model::RayFromImage(params, pixel, ray_in_cam)) {
    return true;
  }
  if constexpr (std::is_same_v<T, double>) {
    return false;
  } else {
    double scalar_params[Model::kNumParams];
    for (int i = 0; i < Model::kNumParams; ++i) {
      scalar_params[i] = internal::ScalarPart(params[i]);
    }
    const double scalar_pixel[2] = {internal::ScalarPart(pixel[0]),
                                    internal::ScalarPart(pixel[1])};
    double scalar_ray[3];
    if (!Model::RayFromImage(scalar_params, scalar_pixel, scalar_ray)) {
      return false;
    }
    for (int i = 0; i < 3; ++i) {
      ray_in_cam[i] = T(scalar_ray[i]);
    }
    return true;
  }
}

// The pixels of a camera along the tangent plane at its ray U: the 2 x 2
// matrix W (row-major) whose column c is d pixel / d t_c, t the coordinates
// in RayTangentBasis(U), so that W times the log map at U is, to first
// order, the pixel offset of the mapped direction. Model is a camera_models/
// model (ImageFromRay); a difference of projections over STEP radians,
// forwards or, where that leaves the lens's field, backwards (relative
// error about STEP); with T a Jet, W carries its derivatives by PARAMS and
// U. PIXEL_OF_U, when the caller has it (U lifted from that pixel at
// PARAMS: its projection, whose derivatives by PARAMS vanish), saves one
// projection. False when a projection fails.
template <typename Model, typename T>
bool PixelFromTangentAtRay(const T* params, const T* u, T* w,
                           double step = 1e-4,
                           const T* pixel_of_u = nullptr) {
  T e[2][3];
  RayTangentBasis(u, e[0], e[1]);
  T centre[2];
  if (pixel_of_u != nullptr) {
    centre[0] = pixel_of_u[0];
    centre[1] = pixel_of_u[1];
  } else if (!Model::ImageFromRay(params, u, centre)) {
    return false;
  }
  for (int c = 0; c < 2; ++c) {
    bool projected = false;
    for (const double h : {step, -step}) {
      const T moved_ray[3] = {u[0] + T(h) * e[c][0], u[1] + T(h) * e[c][1],
                              u[2] + T(h) * e[c][2]};
      T moved[2];
      if (Model::ImageFromRay(params, moved_ray, moved)) {
        w[c] = (moved[0] - centre[0]) / T(h);
        w[2 + c] = (moved[1] - centre[1]) / T(h);
        projected = true;
        break;
      }
    }
    if (!projected) return false;
  }
  return true;
}

}  // namespace sphera
