// The angular reprojection residual in COLMAP 4.x's bundle adjustment and
// pose refinement.
//
// For a spherical camera the residual of an observation is the log map of the
// unit sphere at the observed ray u = RayFromImage(params, pixel), applied to
// the direction of the point v = cam_from_world X (estimators/
// angular_residual.h):
//
//   r = theta * (e1 . w, e2 . w) / |w|,  w = v - (u . v) u,
//   theta = atan2(|w|, u . v),
//
// so |r| is the geodesic angle between u and v (no image seam, no weight that
// grows towards the poles, smooth at zero). It is divided by the camera's
// radians per pixel at the current parameters (a unit conversion, not
// differentiated), so that robust-loss scales and error statistics stay in
// pixels. Intrinsics enter through u, so they can be refined.
//
// Each functor below has the parameter blocks of the upstream pixel functor
// of the same name without "Angular" (reprojection_error.h), so that
// CreateSphereCameraCostFunction can put one in the other's place.
#pragma once

#include "colmap/estimators/cost_functions/reprojection_error.h"
#include "colmap/scene/camera.h"
#include "colmap_ext/estimators/sphere_residual_type.h"

#include "camera_models/common.h"
#include "camera_models/equirectangular.h"
#include "estimators/angular_residual.h"

#include <type_traits>

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

// The residual of one observation: the one body behind every functor below.
template <typename CameraModel, typename T>
bool AngularReprojResidual(const T* camera_params,
                           const Eigen::Vector2d& observed_pixel,
                           const Eigen::Matrix<T, 3, 1>& point3D_in_cam,
                           T* residuals) {
  using SphereModel = typename SphereMathOf<CameraModel>::type;
  if constexpr (std::is_void_v<SphereModel>) {
    return false;
  } else {
    const T pixel[2] = {T(observed_pixel.x()), T(observed_pixel.y())};
    T observed_ray[3];
    if (!SphereModel::RayFromImage(camera_params, pixel, observed_ray)) {
      return false;
    }
    sphera::AngularLogResidual(observed_ray, point3D_in_cam.data(), residuals);
    double scalar_params[CameraModel::num_params];
    for (size_t i = 0; i < CameraModel::num_params; ++i) {
      scalar_params[i] = sphera::internal::ScalarPart(camera_params[i]);
    }
    const T pixels_per_radian(1.0 / SphereModel::PixelToAngle(scalar_params));
    residuals[0] *= pixels_per_radian;
    residuals[1] *= pixels_per_radian;
    return true;
  }
}

template <typename CameraModel>
class AngularReprojErrorCostFunctor
    : public AutoDiffCostFunctor<AngularReprojErrorCostFunctor<CameraModel>,
                                 2,
                                 3,
                                 7,
                                 CameraModel::num_params> {
 public:
  explicit AngularReprojErrorCostFunctor(const Eigen::Vector2d& point2D)
      : point2D_(point2D) {}

  template <typename T>
  bool operator()(const T* const point3D_in_world,
                  const T* const cam_from_world,
                  const T* const camera_params,
                  T* residuals) const {
    const Eigen::Matrix<T, 3, 1> point3D_in_cam =
        EigenQuaternionMap<T>(cam_from_world) *
            EigenVector3Map<T>(point3D_in_world) +
        EigenVector3Map<T>(cam_from_world + 4);
    return AngularReprojResidual<CameraModel>(
        camera_params, point2D_, point3D_in_cam, residuals);
  }

 private:
  const Eigen::Vector2d point2D_;
};

template <typename CameraModel>
class AngularReprojErrorConstantPoseCostFunctor
    : public AutoDiffCostFunctor<
          AngularReprojErrorConstantPoseCostFunctor<CameraModel>,
          2,
          3,
          CameraModel::num_params> {
 public:
  AngularReprojErrorConstantPoseCostFunctor(const Eigen::Vector2d& point2D,
                                            const Rigid3d& cam_from_world)
      : point2D_(point2D), cam_from_world_(cam_from_world.ToMatrix()) {}

  template <typename T>
  bool operator()(const T* const point3D_in_world,
                  const T* const camera_params,
                  T* residuals) const {
    const Eigen::Matrix<T, 3, 1> point3D_in_cam =
        cam_from_world_.leftCols<3>().cast<T>() *
            EigenVector3Map<T>(point3D_in_world) +
        cam_from_world_.col(3).cast<T>();
    return AngularReprojResidual<CameraModel>(
        camera_params, point2D_, point3D_in_cam, residuals);
  }

 private:
  const Eigen::Vector2d point2D_;
  const Eigen::Matrix3x4d cam_from_world_;
};

template <typename CameraModel>
class AngularReprojErrorConstantPoint3DCostFunctor
    : public AutoDiffCostFunctor<
          AngularReprojErrorConstantPoint3DCostFunctor<CameraModel>,
          2,
          7,
          CameraModel::num_params> {
 public:
  AngularReprojErrorConstantPoint3DCostFunctor(
      const Eigen::Vector2d& point2D, const Eigen::Vector3d& point3D_in_world)
      : point3D_in_world_(point3D_in_world), reproj_cost_(point2D) {}

  template <typename T>
  bool operator()(const T* const cam_from_world,
                  const T* const camera_params,
                  T* residuals) const {
    const Eigen::Matrix<T, 3, 1> point3D_in_world = point3D_in_world_.cast<T>();
    return reproj_cost_(
        point3D_in_world.data(), cam_from_world, camera_params, residuals);
  }

 private:
  const Eigen::Vector3d point3D_in_world_;
  const AngularReprojErrorCostFunctor<CameraModel> reproj_cost_;
};

template <typename CameraModel>
class AngularRigReprojErrorCostFunctor
    : public AutoDiffCostFunctor<AngularRigReprojErrorCostFunctor<CameraModel>,
                                 2,
                                 3,
                                 7,
                                 7,
                                 CameraModel::num_params> {
 public:
  explicit AngularRigReprojErrorCostFunctor(const Eigen::Vector2d& point2D)
      : point2D_(point2D) {}

  template <typename T>
  bool operator()(const T* const point3D_in_world,
                  const T* const cam_from_rig,
                  const T* const rig_from_world,
                  const T* const camera_params,
                  T* residuals) const {
    const Eigen::Matrix<T, 3, 1> point3D_in_cam =
        EigenQuaternionMap<T>(cam_from_rig) *
            (EigenQuaternionMap<T>(rig_from_world) *
                 EigenVector3Map<T>(point3D_in_world) +
             EigenVector3Map<T>(rig_from_world + 4)) +
        EigenVector3Map<T>(cam_from_rig + 4);
    return AngularReprojResidual<CameraModel>(
        camera_params, point2D_, point3D_in_cam, residuals);
  }

 private:
  const Eigen::Vector2d point2D_;
};

template <typename CameraModel>
class AngularRigReprojErrorConstantRigCostFunctor
    : public AutoDiffCostFunctor<
          AngularRigReprojErrorConstantRigCostFunctor<CameraModel>,
          2,
          3,
          7,
          CameraModel::num_params> {
 public:
  AngularRigReprojErrorConstantRigCostFunctor(const Eigen::Vector2d& point2D,
                                              const Rigid3d& cam_from_rig)
      : cam_from_rig_(cam_from_rig), reproj_cost_(point2D) {}

  template <typename T>
  bool operator()(const T* const point3D_in_world,
                  const T* const rig_from_world,
                  const T* const camera_params,
                  T* residuals) const {
    const Eigen::Matrix<T, 7, 1> cam_from_rig = cam_from_rig_.params.cast<T>();
    return reproj_cost_(point3D_in_world,
                        cam_from_rig.data(),
                        rig_from_world,
                        camera_params,
                        residuals);
  }

 private:
  const Rigid3d cam_from_rig_;
  const AngularRigReprojErrorCostFunctor<CameraModel> reproj_cost_;
};

// The angular functor that takes the place of an upstream pixel functor.
template <template <typename> class PixelFunctor>
struct AngularFunctorOf;
template <>
struct AngularFunctorOf<ReprojErrorCostFunctor> {
  template <typename M>
  using type = AngularReprojErrorCostFunctor<M>;
};
template <>
struct AngularFunctorOf<ReprojErrorConstantPoseCostFunctor> {
  template <typename M>
  using type = AngularReprojErrorConstantPoseCostFunctor<M>;
};
template <>
struct AngularFunctorOf<ReprojErrorConstantPoint3DCostFunctor> {
  template <typename M>
  using type = AngularReprojErrorConstantPoint3DCostFunctor<M>;
};
template <>
struct AngularFunctorOf<RigReprojErrorCostFunctor> {
  template <typename M>
  using type = AngularRigReprojErrorCostFunctor<M>;
};
template <>
struct AngularFunctorOf<RigReprojErrorConstantRigCostFunctor> {
  template <typename M>
  using type = AngularRigReprojErrorConstantRigCostFunctor<M>;
};

// CreateCameraCostFunction<PixelFunctor>, with the angular residual in its
// place for a spherical camera when `residual` is ANGULAR.
template <template <typename> class PixelFunctor, typename... Args>
ceres::CostFunction* CreateSphereCameraCostFunction(
    const SphereResidualType residual, const Camera& camera, Args&&... args) {
  if (residual == SphereResidualType::ANGULAR && camera.IsSpherical()) {
    return CreateCameraCostFunction<
        AngularFunctorOf<PixelFunctor>::template type>(
        camera.model_id, std::forward<Args>(args)...);
  }
  return CreateCameraCostFunction<PixelFunctor>(camera.model_id,
                                                std::forward<Args>(args)...);
}

}  // namespace colmap
