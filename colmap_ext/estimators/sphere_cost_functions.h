// Bundle adjustment residual for the sphere camera models.
//
// Included by colmap/estimators/cost_functions.h after ReprojErrorCostFunction;
// not meant to be included alone. For a sphere camera model, COLMAP's
// ReprojErrorCostFunction<CameraModel> (and so the constant-pose and
// constant-point variants derived from it, used by bundle adjustment and pose
// refinement) is replaced by the exact angular error between the observed ray
// u = RayFromImage(params, pixel) and the predicted direction v = R X + t:
//
//   r = theta * (e1 . w, e2 . w) / |w|,  w = v - (u . v) u,
//   theta = atan2(|w|, u . v)                       (log map of S² at u)
//
// so |r| is the geodesic angle (paper Eq. 4): no image seam, no weighting
// that grows towards the poles, smooth at zero. The residual is divided by
// the camera's radians per pixel (a unit conversion, taken at the current
// parameters and not differentiated), so that COLMAP's robust-loss scales and
// error statistics stay in pixels.
// Intrinsics that the model refines enter through u.
#pragma once

#include "camera_models/common.h"
#include "estimators/angular_residual.h"

namespace colmap {

template <typename CameraModel>
class SphereReprojErrorCostFunction {
 public:
  explicit SphereReprojErrorCostFunction(const Eigen::Vector2d& point2D)
      : observed_x_(point2D(0)), observed_y_(point2D(1)) {}

  static ceres::CostFunction* Create(const Eigen::Vector2d& point2D) {
    return (
        new ceres::AutoDiffCostFunction<ReprojErrorCostFunction<CameraModel>,
                                        2,
                                        4,
                                        3,
                                        3,
                                        CameraModel::num_params>(
            new ReprojErrorCostFunction<CameraModel>(point2D)));
  }

  template <typename T>
  bool operator()(const T* const cam_from_world_rotation,
                  const T* const cam_from_world_translation,
                  const T* const point3D,
                  const T* const camera_params,
                  T* residuals) const {
    const Eigen::Matrix<T, 3, 1> point3D_in_cam =
        EigenQuaternionMap<T>(cam_from_world_rotation) *
            EigenVector3Map<T>(point3D) +
        EigenVector3Map<T>(cam_from_world_translation);
    const T pixel[2] = {T(observed_x_), T(observed_y_)};
    T observed_ray[3];
    if (!CameraModel::sphere_model::RayFromImage(
            camera_params, pixel, observed_ray)) {
      return false;
    }
    sphera::AngularLogResidual(observed_ray, point3D_in_cam.data(), residuals);

    double scalar_params[CameraModel::num_params];
    for (size_t i = 0; i < CameraModel::num_params; ++i) {
      scalar_params[i] = sphera::internal::ScalarPart(camera_params[i]);
    }
    const T px_per_rad(
        1.0 / CameraModel::sphere_model::PixelToAngle(scalar_params));
    residuals[0] *= px_per_rad;
    residuals[1] *= px_per_rad;
    return true;
  }

 private:
  const double observed_x_;
  const double observed_y_;
};

#define SPHERA_SPHERE_REPROJ_ERROR(CameraModel)                          \
  template <>                                                            \
  class ReprojErrorCostFunction<CameraModel>                             \
      : public SphereReprojErrorCostFunction<CameraModel> {              \
   public:                                                               \
    using SphereReprojErrorCostFunction<                                 \
        CameraModel>::SphereReprojErrorCostFunction;                     \
  };

SPHERA_SPHERE_REPROJ_ERROR(EUCMCameraModel)
SPHERA_SPHERE_REPROJ_ERROR(EquirectangularCameraModel)
SPHERA_SPHERE_REPROJ_ERROR(UnifiedOmniCameraModel)
SPHERA_SPHERE_REPROJ_ERROR(DoubleSphereCameraModel)

#undef SPHERA_SPHERE_REPROJ_ERROR

}  // namespace colmap
