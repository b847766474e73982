// The angular reprojection residual of one observation of a spherical
// camera, taken to pixels by the camera's own derivative at the observed
// pixel: the one body behind bundle adjustment's angular costs
// (sphere_cost_functions.h) and the reprojection error by which COLMAP
// filters observations and reports its errors (scene/
// sphere_reprojection_error.h), so that both measure an observation alike.
// Templates on COLMAP's camera models; no Ceres.
#pragma once

#include "colmap/sensor/models.h"

#include "camera_models/common.h"
#include "camera_models/equirectangular.h"
#include "estimators/angular_residual.h"

#include <type_traits>

#include <Eigen/Core>
#include <Eigen/SVD>

namespace colmap {

// The camera_models/ math of a spherical camera model: its sphere_model, or
// for upstream's EQUIRECTANGULAR our model of the same convention; void for
// the perspective models, which never take the angular residual.
template <typename CameraModel, typename = void>
struct SphereMathOf {
  using type = std::conditional_t<CameraModel::model_id ==
                                      CameraModelId::kEquirectangular,
                                  sphera::EquirectangularModel,
                                  void>;
};
template <typename CameraModel>
struct SphereMathOf<CameraModel,
                    std::void_t<typename CameraModel::sphere_model>> {
  using type = typename CameraModel::sphere_model;
};

// The pixels per radian of a spherical camera with CAMERA_PARAMS: the unit of
// its angular residual (1 for the perspective models, which never take it).
template <typename CameraModel>
double AngularPixelsPerRadian(const double* camera_params) {
  using SphereModel = typename SphereMathOf<CameraModel>::type;
  if constexpr (std::is_void_v<SphereModel>) {
    return 1.0;
  } else {
    return 1.0 / SphereModel::PixelToAngle(camera_params);
  }
}

// How the angular residual of one observation is taken to pixels
// (AngularResidualWeight): by the camera's own derivative at the observed
// pixel (AngularWeightAt), or by one scale for every direction, the
// camera's pixels per radian on its axis at the parameters it was made
// with.
struct AngularWeight {
  bool isotropic = true;
  double scale = 1;
};

// The metric of the angular residual of the observation at PIXEL. Only
// EQUIRECTANGULAR (whose pixels per radian of longitude grow without bound
// towards the poles), a pixel without a ray or projection, and pixels per
// radian beyond a tenth or ten times the camera's on its axis (near a
// singular point of the model) take the isotropic scale.
template <typename CameraModel>
AngularWeight AngularResidualWeight(const double* camera_params,
                                    const Eigen::Vector2d& pixel) {
  using SphereModel = typename SphereMathOf<CameraModel>::type;
  AngularWeight weight;
  weight.scale = AngularPixelsPerRadian<CameraModel>(camera_params);
  if constexpr (!std::is_void_v<SphereModel> &&
                CameraModel::model_id != CameraModelId::kEquirectangular) {
    const double pixel_xy[2] = {pixel.x(), pixel.y()};
    double ray[3];
    Eigen::Matrix<double, 2, 2, Eigen::RowMajor> w;
    if (!SphereModel::RayFromImage(camera_params, pixel_xy, ray) ||
        !sphera::PixelFromTangentAtRay<SphereModel>(
            camera_params, ray, w.data())) {
      return weight;
    }
    if (!w.allFinite()) {
      // JacobiSVD need not return on a non-finite matrix.
      return weight;
    }
    const Eigen::Vector2d pixels_per_radian =
        Eigen::JacobiSVD<Eigen::Matrix2d>(w).singularValues();
    weight.isotropic = !pixels_per_radian.allFinite() ||
                       !(pixels_per_radian(0) < 10 * weight.scale) ||
                       !(pixels_per_radian(1) * 10 > weight.scale);
  }
  return weight;
}

// The 2 x 2 map of the log map at OBSERVED_RAY (in its RayTangentBasis) to
// pixels at CAMERA_PARAMS: the camera's pixels along the tangent plane at
// the ray as the camera now is (sphera::PixelFromTangentAtRay), so that W r
// is the pixel residual to first order at every value of the parameters
// being refined (see the header comment); with T a Jet it carries the
// metric's own derivatives by the parameters. OBSERVED_RAY is
// OBSERVED_PIXEL lifted at CAMERA_PARAMS. WEIGHT's one scale where
// AngularResidualWeight found none or the projection fails.
template <typename CameraModel, typename T>
Eigen::Matrix<T, 2, 2> AngularWeightAt(const AngularWeight& weight,
                                       const T* camera_params,
                                       const T* observed_pixel,
                                       const T* observed_ray) {
  using SphereModel = typename SphereMathOf<CameraModel>::type;
  Eigen::Matrix<T, 2, 2> isotropic;
  isotropic << T(weight.scale), T(0), T(0), T(weight.scale);
  if constexpr (std::is_void_v<SphereModel> ||
                CameraModel::model_id == CameraModelId::kEquirectangular) {
    return isotropic;
  } else {
    Eigen::Matrix<T, 2, 2, Eigen::RowMajor> w;
    if (weight.isotropic ||
        !sphera::PixelFromTangentAtRay<SphereModel>(
            camera_params, observed_ray, w.data(), 1e-4, observed_pixel)) {
      return isotropic;
    }
    return w;
  }
}

// The residual of one observation: the one body behind every functor below,
// the log map taken to pixels by WEIGHT (AngularResidualWeight).
template <typename CameraModel, typename T>
bool AngularReprojResidual(const T* camera_params,
                           const Eigen::Vector2d& observed_pixel,
                           const Eigen::Matrix<T, 3, 1>& point3D_in_cam,
                           const AngularWeight& weight,
                           T* residuals) {
  using SphereModel = typename SphereMathOf<CameraModel>::type;
  if constexpr (std::is_void_v<SphereModel>) {
    return false;
  } else {
    const T pixel[2] = {T(observed_pixel.x()), T(observed_pixel.y())};
    T observed_ray[3];
    if (!sphera::RayFromImageOrScalarRay<SphereModel>(
            camera_params, pixel, observed_ray)) {
      return false;
    }
    Eigen::Matrix<T, 2, 1> log_map;
    sphera::AngularLogResidual(
        observed_ray, point3D_in_cam.data(), log_map.data());
    Eigen::Map<Eigen::Matrix<T, 2, 1>> residual_map(residuals);
    residual_map =
        AngularWeightAt<CameraModel>(
            weight, camera_params, pixel, observed_ray) *
        log_map;
    return true;
  }
}

}  // namespace colmap
