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
//
// Also here: the pixel residual for every camera model (sphere models project
// with ImageFromRay), which BundleAdjustmentOptions::sphere_residual = "pixel"
// selects for the sphere models, and `colmap sphere_bundle_adjuster
// --residual pixel` uses for comparisons.
#pragma once

#include <string>
#include <type_traits>

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

template <typename M, typename = void>
struct IsSphereCameraModel : std::false_type {};
template <typename M>
struct IsSphereCameraModel<M, std::void_t<typename M::sphere_model>>
    : std::true_type {};

// Pixel reprojection residual x_pred - x_obs for every camera model:
//   x_pred = ImageFromRay(params, R X + t) for the sphere models (any ray in
//   the field of view), ImgFromCam(params, R X + t) for COLMAP's own models.
// EQUIRECTANGULAR (params w, h): the x residual is wrapped into [-w/2, w/2]
// so that a point seen across the seam is not 2 pi away. The wrap offset is
// an integer multiple of w taken from the value (not differentiated). A
// point outside the field of view makes the evaluation fail (Ceres rejects
// the step).
template <typename CameraModel>
class PixelReprojErrorCostFunction {
 public:
  explicit PixelReprojErrorCostFunction(const Eigen::Vector2d& point2D)
      : observed_(point2D) {}

  static ceres::CostFunction* Create(const Eigen::Vector2d& point2D) {
    return new ceres::AutoDiffCostFunction<PixelReprojErrorCostFunction, 2, 4,
                                           3, 3, CameraModel::num_params>(
        new PixelReprojErrorCostFunction(point2D));
  }

  template <typename T>
  bool operator()(const T* const cam_from_world_rotation,
                  const T* const cam_from_world_translation,
                  const T* const point3D, const T* const camera_params,
                  T* residuals) const {
    const Eigen::Matrix<T, 3, 1> v =
        EigenQuaternionMap<T>(cam_from_world_rotation) *
            EigenVector3Map<T>(point3D) +
        EigenVector3Map<T>(cam_from_world_translation);
    T pixel[2];
    if constexpr (IsSphereCameraModel<CameraModel>::value) {
      if (!CameraModel::sphere_model::ImageFromRay(camera_params, v.data(),
                                                   pixel)) {
        return false;
      }
    } else {
      if (!(v[2] > T(0))) return false;
      CameraModel::ImgFromCam(camera_params, v[0], v[1], v[2], &pixel[0],
                              &pixel[1]);
    }
    residuals[0] = pixel[0] - T(observed_(0));
    residuals[1] = pixel[1] - T(observed_(1));
    if (CameraModel::model_id == CameraModelId::kEquirectangular) {
      const double w = sphera::internal::ScalarPart(camera_params[0]);
      const double k =
          std::round(sphera::internal::ScalarPart(residuals[0]) / w);
      residuals[0] -= T(k * w);
    }
    return true;
  }

 private:
  const Eigen::Vector2d observed_;
};

// The pixel residual with the pose held constant (bundle adjustment of
// images whose pose is fixed).
template <typename CameraModel>
class PixelReprojErrorConstantPoseCostFunction
    : public PixelReprojErrorCostFunction<CameraModel> {
  using Parent = PixelReprojErrorCostFunction<CameraModel>;

 public:
  PixelReprojErrorConstantPoseCostFunction(const Rigid3d& cam_from_world,
                                           const Eigen::Vector2d& point2D)
      : Parent(point2D), cam_from_world_(cam_from_world) {}

  static ceres::CostFunction* Create(const Rigid3d& cam_from_world,
                                     const Eigen::Vector2d& point2D) {
    return new ceres::AutoDiffCostFunction<
        PixelReprojErrorConstantPoseCostFunction, 2, 3,
        CameraModel::num_params>(
        new PixelReprojErrorConstantPoseCostFunction(cam_from_world, point2D));
  }

  template <typename T>
  bool operator()(const T* const point3D, const T* const camera_params,
                  T* residuals) const {
    const Eigen::Quaternion<T> rotation = cam_from_world_.rotation.cast<T>();
    const Eigen::Matrix<T, 3, 1> translation =
        cam_from_world_.translation.cast<T>();
    return Parent::operator()(rotation.coeffs().data(), translation.data(),
                              point3D, camera_params, residuals);
  }

 private:
  const Rigid3d cam_from_world_;
};

// Bundle adjustment residual of one observation. For the sphere camera
// models `sphere_residual` ("angular", the default, or "pixel";
// BundleAdjustmentOptions::sphere_residual) chooses between the angular
// residual above and the pixel residual; COLMAP's own models always use
// COLMAP's pixel residual.
inline bool UseSpherePixelResidual(const std::string& sphere_residual,
                                   const CameraModelId camera_model_id) {
  return sphere_residual == "pixel" && CameraModelIsSphere(camera_model_id);
}

inline ceres::CostFunction* BundleAdjustmentCostFunction(
    const std::string& sphere_residual,
    const CameraModelId camera_model_id,
    const Eigen::Vector2d& point2D) {
  if (UseSpherePixelResidual(sphere_residual, camera_model_id)) {
    return CameraCostFunction<PixelReprojErrorCostFunction>(camera_model_id,
                                                            point2D);
  }
  return CameraCostFunction<ReprojErrorCostFunction>(camera_model_id, point2D);
}

inline ceres::CostFunction* BundleAdjustmentConstantPoseCostFunction(
    const std::string& sphere_residual,
    const CameraModelId camera_model_id,
    const Rigid3d& cam_from_world,
    const Eigen::Vector2d& point2D) {
  if (UseSpherePixelResidual(sphere_residual, camera_model_id)) {
    return CameraCostFunction<PixelReprojErrorConstantPoseCostFunction>(
        camera_model_id, cam_from_world, point2D);
  }
  return CameraCostFunction<ReprojErrorConstantPoseCostFunction>(
      camera_model_id, cam_from_world, point2D);
}

}  // namespace colmap
