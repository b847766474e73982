#include "calibration/lens_projections.h"

#include <cmath>

#include "camera_models/registry.h"

namespace sphera {
namespace {

double Coeff(const std::vector<double>& coeffs, size_t i) {
  return i < coeffs.size() ? coeffs[i] : 0.0;
}

// m of the projection: our models with unit focal length, zero principal
// point and no distortion.
bool ProjectToPlane(LensProjection projection,
                    const std::vector<double>& params,
                    const Eigen::Vector3d& ray_in_cam, Eigen::Vector2d* m) {
  switch (projection) {
    case LensProjection::kPinhole:
      return ImageFromRay(static_cast<int>(ModelId::kPinhole), {1, 1, 0, 0},
                          ray_in_cam, m);
    case LensProjection::kUnified:
      return ImageFromRay(static_cast<int>(ModelId::kUnifiedOmni),
                          {1, 1, 0, 0, Coeff(params, 0), 0, 0, 0, 0},
                          ray_in_cam, m);
    case LensProjection::kDoubleSphere:
      return ImageFromRay(static_cast<int>(ModelId::kDoubleSphere),
                          {1, 1, 0, 0, Coeff(params, 0), Coeff(params, 1)},
                          ray_in_cam, m);
    case LensProjection::kEUCM:
      return ImageFromRay(static_cast<int>(ModelId::kEUCM),
                          {1, 1, 0, 0, Coeff(params, 0), Coeff(params, 1)},
                          ray_in_cam, m);
  }
  return false;
}

Eigen::Vector2d Distort(LensDistortion distortion,
                        const std::vector<double>& k,
                        const Eigen::Vector2d& m) {
  const double u = m.x(), v = m.y();
  const double r2 = u * u + v * v;
  const double r = std::sqrt(r2);
  switch (distortion) {
    case LensDistortion::kNone:
      return m;
    case LensDistortion::kRadTan: {
      Eigen::Vector2d md;
      const double coeffs[4] = {Coeff(k, 0), Coeff(k, 1), Coeff(k, 2),
                                Coeff(k, 3)};
      internal::DistortRadTan(coeffs, u, v, &md.x(), &md.y());
      return md;
    }
    case LensDistortion::kEquidistant: {
      if (r < 1e-12) return m;
      const double theta = std::atan(r);
      const double t2 = theta * theta;
      const double theta_d =
          theta * (1 + t2 * (Coeff(k, 0) +
                             t2 * (Coeff(k, 1) +
                                   t2 * (Coeff(k, 2) + t2 * Coeff(k, 3)))));
      return m * (theta_d / r);
    }
    case LensDistortion::kFov: {
      const double w = Coeff(k, 0);
      if (r < 1e-12 || std::abs(w) < 1e-12) return m;
      return m * (std::atan(2 * r * std::tan(w / 2)) / (w * r));
    }
    case LensDistortion::kRational: {
      const double radial =
          (1 + r2 * (Coeff(k, 0) + r2 * (Coeff(k, 1) + r2 * Coeff(k, 4)))) /
          (1 + r2 * (Coeff(k, 5) + r2 * (Coeff(k, 6) + r2 * Coeff(k, 7))));
      const double p1 = Coeff(k, 2), p2 = Coeff(k, 3);
      return {u * radial + 2 * p1 * u * v + p2 * (r2 + 2 * u * u) +
                  Coeff(k, 8) * r2 + Coeff(k, 9) * r2 * r2,
              v * radial + p1 * (r2 + 2 * v * v) + 2 * p2 * u * v +
                  Coeff(k, 10) * r2 + Coeff(k, 11) * r2 * r2};
    }
  }
  return m;
}

}  // namespace

bool GenericLens::ImageFromRay(const Eigen::Vector3d& ray_in_cam,
                               Eigen::Vector2d* pixel) const {
  Eigen::Vector2d m;
  if (!ProjectToPlane(projection, projection_params, ray_in_cam, &m)) {
    return false;
  }
  const Eigen::Vector2d md = Distort(distortion, distortion_coeffs, m);
  *pixel = {fx * md.x() + skew * md.y() + cx, fy * md.y() + cy};
  return pixel->allFinite();
}

bool OCamPolynomialLens::RayFromImage(const Eigen::Vector2d& pixel,
                                      Eigen::Vector3d* ray_in_cam) const {
  const double det = c - d * e;
  if (det == 0) return false;
  const double row = pixel.y() - cy;
  const double col = pixel.x() - cx;
  const double s_row = (row - d * col) / det;
  const double s_col = (c * col - e * row) / det;
  const double rho = std::hypot(s_row, s_col);
  double f = 0;
  for (size_t i = pol.size(); i-- > 0;) f = f * rho + pol[i];
  *ray_in_cam = Eigen::Vector3d(s_col, s_row, -f);
  return ray_in_cam->allFinite() && ray_in_cam->norm() > 0;
}

}  // namespace sphera
