// Shared helpers of the camera models: scalar access for ceres::Jet, the
// radial-tangential (OpenCV / Kalibr "radtan") distortion and its inverse, and
// parameter validation messages.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iomanip>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <ceres/jet.h>

namespace sphera {
namespace internal {

constexpr double kPi = 3.14159265358979323846;

// Value part of a scalar; used only for control flow (convergence tests), never
// inside a differentiated expression.
inline double ScalarPart(double x) { return x; }
template <typename T, int N>
double ScalarPart(const ceres::Jet<T, N>& x) {
  return ScalarPart(x.a);
}

// ray_in_cam = (x, y, z) / |(x, y, z)|; false for the zero vector.
template <typename T>
bool NormalizeRay(const T& x, const T& y, const T& z, T* ray_in_cam) {
  using std::sqrt;
  const T norm2 = x * x + y * y + z * z;
  if (!(norm2 > T(0))) return false;
  const T inv_norm = T(1) / sqrt(norm2);
  ray_in_cam[0] = x * inv_norm;
  ray_in_cam[1] = y * inv_norm;
  ray_in_cam[2] = z * inv_norm;
  return true;
}

// Radial-tangential distortion of normalized coordinates (u, v), exactly as
// COLMAP's OPENCV model, k = (k1, k2, p1, p2):
//   r2 = u² + v², radial = k1 r2 + k2 r2²
//   ud = u + u radial + 2 p1 u v + p2 (r2 + 2 u²)
//   vd = v + v radial + 2 p2 u v + p1 (r2 + 2 v²)
// If jacobian != nullptr it receives d(ud, vd)/d(u, v), row-major 2x2.
template <typename T>
void DistortRadTan(const T* k, const T& u, const T& v, T* ud, T* vd,
                   T* jacobian = nullptr) {
  const T& k1 = k[0];
  const T& k2 = k[1];
  const T& p1 = k[2];
  const T& p2 = k[3];
  const T u2 = u * u;
  const T v2 = v * v;
  const T uv = u * v;
  const T r2 = u2 + v2;
  const T radial = k1 * r2 + k2 * r2 * r2;
  *ud = u + u * radial + T(2) * p1 * uv + p2 * (r2 + T(2) * u2);
  *vd = v + v * radial + T(2) * p2 * uv + p1 * (r2 + T(2) * v2);
  if (jacobian != nullptr) {
    // d radial / d u = 2 u (k1 + 2 k2 r2), likewise for v.
    const T dradial = T(2) * (k1 + T(2) * k2 * r2);
    jacobian[0] = T(1) + radial + u2 * dradial + T(2) * p1 * v + T(6) * p2 * u;
    jacobian[1] = uv * dradial + T(2) * p1 * u + T(2) * p2 * v;
    jacobian[2] = uv * dradial + T(2) * p2 * v + T(2) * p1 * u;
    jacobian[3] = T(1) + radial + v2 * dradial + T(6) * p1 * v + T(2) * p2 * u;
  }
}

// One Newton step of the inversion of DistortRadTan at (u, v) towards the
// distorted point (ud, vd): the step to subtract. False where the map's
// Jacobian is singular or not finite.
template <typename T>
bool RadTanNewtonStep(const T* k, const T& u, const T& v, const T& ud,
                      const T& vd, T* step_u, T* step_v) {
  T du, dv, J[4];
  DistortRadTan(k, u, v, &du, &dv, J);
  const T det = J[0] * J[3] - J[1] * J[2];
  if (!(ScalarPart(det) != 0.0) || !std::isfinite(ScalarPart(det))) {
    return false;
  }
  const T res_u = du - ud;
  const T res_v = dv - vd;
  *step_u = (J[3] * res_u - J[1] * res_v) / det;
  *step_v = (J[0] * res_v - J[2] * res_u) / det;
  return true;
}

// Inverts DistortRadTan by Newton's method on the 2D map, starting at the
// distorted point. Stops when the step is below 1e-14 relative to |(u, v)|.
// False if the iteration does not converge (distortion not invertible there).
inline bool UndistortRadTanScalar(const double* k, double ud, double vd,
                                  double* u, double* v) {
  constexpr int kMaxIterations = 100;
  constexpr double kRelativeTolerance = 1e-14;
  double cur_u = ud;
  double cur_v = vd;
  for (int i = 0; i < kMaxIterations; ++i) {
    double step_u, step_v;
    if (!RadTanNewtonStep(k, cur_u, cur_v, ud, vd, &step_u, &step_v)) {
      return false;
    }
    cur_u -= step_u;
    cur_v -= step_v;
    const double step2 = step_u * step_u + step_v * step_v;
    const double norm2 = cur_u * cur_u + cur_v * cur_v;
    if (!std::isfinite(norm2)) return false;
    if (step2 <= kRelativeTolerance * kRelativeTolerance * norm2) {
      *u = cur_u;
      *v = cur_v;
      return true;
    }
  }
  // Last-ulp oscillation can prevent the step test; accept a tiny residual.
  double du, dv;
  DistortRadTan(k, cur_u, cur_v, &du, &dv);
  if (!(std::hypot(du - ud, dv - vd) <= 1e-12 * (1.0 + std::hypot(ud, vd)))) {
    return false;
  }
  *u = cur_u;
  *v = cur_v;
  return true;
}

// The same for any scalar type. For ceres::Jet the root is found on the value
// parts alone and followed by one Newton step in T from that root: the step
// leaves the value unchanged (its residual is at rounding level) and gives the
// derivative parts exactly the implicit-function derivative
// -J^-1 (d distort / d k dk - d(ud, vd)), at the cost of one Jacobian in T
// instead of one per iteration (the angular residual of a distorted lens
// unprojects every observation with Jets in every bundle adjustment).
template <typename T>
bool UndistortRadTan(const T* k, const T& ud, const T& vd, T* u, T* v) {
  if constexpr (std::is_same_v<T, double>) {
    return UndistortRadTanScalar(k, ud, vd, u, v);
  } else {
    const double k_value[4] = {ScalarPart(k[0]), ScalarPart(k[1]),
                               ScalarPart(k[2]), ScalarPart(k[3])};
    double u_value, v_value;
    if (!UndistortRadTanScalar(k_value, ScalarPart(ud), ScalarPart(vd),
                               &u_value, &v_value)) {
      return false;
    }
    const T root_u(u_value);
    const T root_v(v_value);
    T step_u, step_v;
    if (!RadTanNewtonStep(k, root_u, root_v, ud, vd, &step_u, &step_v)) {
      return false;
    }
    *u = root_u - step_u;
    *v = root_v - step_v;
    return true;
  }
}

// The radius, in normalized coordinates ((px - cx) / fx, (py - cy) / fy), of
// the image circle a width x height frame shows about the principal point: the
// disc that reaches the frame's farthest edge. A fisheye's image circle lies
// inside it, whether the circle is whole in the frame or cropped by two of its
// edges (the corners beyond it are dark); only a full-frame fisheye shows
// rays beyond it, in the corners.
inline double FrameCircleRadius(const double* params, int width, int height) {
  return std::max(std::max(params[2], width - params[2]) / params[0],
                  std::max(params[3], height - params[3]) / params[1]);
}

// ---------------------------------------------------------------------------
// Parameter validation. Messages have the form "<MODEL>: <name>=<value> ...".

inline std::string FormatNumber(double value) {
  std::ostringstream stream;
  stream << std::setprecision(10) << value;
  return stream.str();
}

// Name of parameter idx in a comma-separated params_info string.
inline std::string ParamName(const char* params_info, int idx) {
  std::stringstream stream(params_info);
  std::string name;
  for (int i = 0; std::getline(stream, name, ','); ++i) {
    if (i == idx) {
      const size_t begin = name.find_first_not_of(' ');
      const size_t end = name.find_last_not_of(' ');
      return begin == std::string::npos ? "" : name.substr(begin, end - begin + 1);
    }
  }
  return "param" + std::to_string(idx);
}

inline std::string CheckParamCount(const char* model_name,
                                   const char* params_info, int expected,
                                   size_t given) {
  if (given == static_cast<size_t>(expected)) return "";
  return std::string(model_name) + ": expected " + std::to_string(expected) +
         " params (" + params_info + "), got " + std::to_string(given);
}

inline std::string CheckAllFinite(const char* model_name,
                                  const char* params_info,
                                  const std::vector<double>& params) {
  for (size_t i = 0; i < params.size(); ++i) {
    if (!std::isfinite(params[i])) {
      return std::string(model_name) + ": " +
             ParamName(params_info, static_cast<int>(i)) + "=" +
             FormatNumber(params[i]) + " is not finite";
    }
  }
  return "";
}

inline std::string CheckPositive(const char* model_name,
                                 const char* params_info,
                                 const std::vector<double>& params, int idx) {
  if (params[idx] > 0) return "";
  return std::string(model_name) + ": " + ParamName(params_info, idx) + "=" +
         FormatNumber(params[idx]) + " must be positive";
}

// lo/hi inclusive unless the corresponding *_open flag is set.
inline std::string CheckInRange(const char* model_name,
                                const char* params_info,
                                const std::vector<double>& params, int idx,
                                double lo, bool lo_open, double hi,
                                bool hi_open) {
  const double value = params[idx];
  const bool ok = (lo_open ? value > lo : value >= lo) &&
                  (hi_open ? value < hi : value <= hi);
  if (ok) return "";
  return std::string(model_name) + ": " + ParamName(params_info, idx) + "=" +
         FormatNumber(value) + " must be in " + (lo_open ? "(" : "[") +
         FormatNumber(lo) + ", " + FormatNumber(hi) + (hi_open ? ")" : "]");
}

// First non-empty message of the focal-length / finiteness checks shared by
// all models with (fx, fy) at indices 0, 1.
inline std::string CheckCountFiniteFocal(const char* model_name,
                                         const char* params_info,
                                         int num_params,
                                         const std::vector<double>& params) {
  if (auto e = CheckParamCount(model_name, params_info, num_params,
                               params.size());
      !e.empty())
    return e;
  if (auto e = CheckAllFinite(model_name, params_info, params); !e.empty())
    return e;
  if (auto e = CheckPositive(model_name, params_info, params, 0); !e.empty())
    return e;
  return CheckPositive(model_name, params_info, params, 1);
}

}  // namespace internal
}  // namespace sphera
