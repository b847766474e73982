// Projections of the lens models that calibration files hold, for the models
// that camera_models/ has no exact counterpart of (then the importer fits one
// of ours to them, calibration/model_conversion.h). Pixels are in COLMAP's
// convention (the centre of the upper-left pixel is (0.5, 0.5)); the callers
// shift the files' principal points, which count from the centre of that
// pixel, by 0.5.
//
// A lens here is a projection of the ray onto a normalised plane m, a
// distortion of m, and the affine map
//   px = fx mdx + skew mdy + cx,  py = fy mdy + cy.
// Projections (ray (x, y, z), d = |ray|):
//   pinhole       m = (x, y) / z,                          visible iff z > 0
//   unified (xi)  m = (x, y) / (z + xi d) (Mei; Kalibr omni, cv::omnidir),
//                 visible as UNIFIED_OMNI (camera_models/unified_omni.h)
//   double sphere (xi, alpha), eucm (alpha, beta): as DOUBLE_SPHERE and EUCM
// Distortions of m, r = |m|:
//   none
//   radtan        k1, k2, p1, p2 (OpenCV, Kalibr radtan)
//   equidistant   k1..k4: md = m theta_d / r, theta = atan(r),
//                 theta_d = theta (1 + k1 theta² + ... + k4 theta⁸)
//   fov           w: md = m atan(2 r tan(w / 2)) / (w r) (Devernay-Faugeras)
//   rational      OpenCV's full pinhole distortion k1, k2, p1, p2, k3, k4,
//                 k5, k6, s1, s2, s3, s4 (cv::calibrateCamera's 4 to 12
//                 coefficients, missing ones 0)
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace sphera {

enum class LensProjection { kPinhole, kUnified, kDoubleSphere, kEUCM };
enum class LensDistortion { kNone, kRadTan, kEquidistant, kFov, kRational };

struct GenericLens {
  LensProjection projection = LensProjection::kPinhole;
  // unified: {xi}; double sphere: {xi, alpha}; eucm: {alpha, beta}.
  std::vector<double> projection_params;
  LensDistortion distortion = LensDistortion::kNone;
  std::vector<double> distortion_coeffs;
  double fx = 0, fy = 0, cx = 0, cy = 0, skew = 0;

  // False when the ray is not visible.
  bool ImageFromRay(const Eigen::Vector3d& ray_in_cam,
                    Eigen::Vector2d* pixel) const;
};

// OCamCalib's lens with a polynomial of any degree (pol = a0, a1, a2, ...)
// and its affine map (camera_models/ocam.h states the conventions):
//   [py - cy; px - cx] = [[c, d], [e, 1]] [s_row; s_col],
//   ray = (s_col, s_row, -f(|s|)),  f(rho) = sum_i pol_i rho^i.
struct OCamPolynomialLens {
  std::vector<double> pol;
  double cx = 0, cy = 0, c = 1, d = 0, e = 0;

  // False when c - d e is zero.
  bool RayFromImage(const Eigen::Vector2d& pixel,
                    Eigen::Vector3d* ray_in_cam) const;
};

}  // namespace sphera
