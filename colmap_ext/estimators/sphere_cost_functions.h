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
// grows towards the poles, smooth at zero). It is taken to pixels so that
// robust-loss scales and error statistics stay in pixels, by the camera's
// own derivative of the pixel by the tangent plane at u, at the parameters
// being refined (AngularWeightAt): W r is then the pixel residual to first
// order, direction included, and stays so while the intrinsics move. A lens
// compresses its image towards the rim radially unlike tangentially (a
// 200-degree Kannala-Brandt lens has 1.7 times as many pixels per radian
// along its rim as on its axis), and the pixels per radian follow the focal
// length: an angle measures a keypoint's pixel noise only through them. A
// fixed scale (the camera's pixels per radian on its axis when the problem
// is built) lets a longer focal length shrink every residual, the noise's
// included: on a rendered 8-lens rig it leaves the focal lengths 0.02-0.05%
// long and the lens centres 0.4 to 1.1 mm off, where this metric gives
// 0.06 to 0.5 mm (docs/rigs.md). EQUIRECTANGULAR keeps one fixed scale: its pixels
// per radian of longitude grow without bound towards the poles. Intrinsics
// enter through u and W, so they can be refined.
//
// Each functor below has the parameter blocks of the upstream pixel functor
// of the same name without "Angular" (reprojection_error.h), so that
// CreateSphereCameraCostFunction can put one in the other's place.  Where
// upstream uses analytic Jacobians (the full and the constant-pose cost), so
// do we: AngularReprojErrorCostFunction and
// AngularReprojErrorConstantPoseCostFunction, tested against the autodiff
// AngularReprojErrorCostFunctor; mapping a 360-degree set with the angular
// residual then costs no more than with the pixel one. The rig costs
// (upstream's are autodiff) are analytic too, tested against an autodiff
// reference: a lens of a rig has 23 to 26 parameters, and autodiff of all of
// them dominated the mapping of rigs.
#pragma once

#include "colmap/estimators/cost_functions/quaternion_utils.h"
#include "colmap/estimators/cost_functions/reprojection_error.h"
#include "colmap/scene/camera.h"
#include "colmap_ext/estimators/angular_pixel_residual.h"
#include "colmap_ext/estimators/sphere_residual_type.h"
#include "colmap_ext/scene/camera_category.h"

#include "estimators/angular_residual.h"

#include <cmath>
#include <type_traits>

namespace colmap {

// The same residual in doubles with analytic derivatives with respect to the
// point in the camera frame (2 x 3, row-major) and, only when asked, to the
// camera parameters (2 x num_params, by forward-mode differentiation of the
// ray lifting alone); either Jacobian may be nullptr.  It equals
// AngularReprojResidual: the same ray, the same log map.
template <typename CameraModel>
bool AngularReprojResidualWithJacobians(const double* camera_params,
                                        const Eigen::Vector2d& observed_pixel,
                                        const double* point3D_in_cam,
                                        const AngularWeight& weight,
                                        double* residuals,
                                        double* J_point_in_cam,
                                        double* J_params) {
  using SphereModel = typename SphereMathOf<CameraModel>::type;
  if constexpr (std::is_void_v<SphereModel>) {
    return false;
  } else {
    constexpr int kNumParams = static_cast<int>(CameraModel::num_params);
    if (J_params == nullptr) {
      const double pixel[2] = {observed_pixel.x(), observed_pixel.y()};
      double observed_ray[3];
      if (!SphereModel::RayFromImage(camera_params, pixel, observed_ray)) {
        return false;
      }
      Eigen::Vector2d log_map;
      Eigen::Matrix<double, 2, 3, Eigen::RowMajor> J_log_map;
      sphera::AngularLogResidualWithJacobian(
          observed_ray,
          point3D_in_cam,
          log_map.data(),
          J_point_in_cam != nullptr ? J_log_map.data() : nullptr);
      const Eigen::Matrix2d w =
          AngularWeightAt<CameraModel>(
              weight, camera_params, pixel, observed_ray);
      Eigen::Map<Eigen::Vector2d> residual_map(residuals);
      residual_map = w * log_map;
      if (J_point_in_cam != nullptr) {
        Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> J_map(
            J_point_in_cam);
        J_map = w * J_log_map;
      }
      return true;
    }
    // Derivatives by the camera parameters in Jets of their number (the
    // ray, the metric and the log map at the point's value); by the point
    // in doubles (the metric does not depend on it).
    using Jet = ceres::Jet<double, kNumParams>;
    Jet params[kNumParams];
    for (int i = 0; i < kNumParams; ++i) {
      params[i] = Jet(camera_params[i], i);
    }
    const Jet pixel[2] = {Jet(observed_pixel.x()), Jet(observed_pixel.y())};
    Jet observed_ray[3];
    if (!sphera::RayFromImageOrScalarRay<SphereModel>(
            params, pixel, observed_ray)) {
      return false;
    }
    const Jet point[3] = {Jet(point3D_in_cam[0]), Jet(point3D_in_cam[1]),
                          Jet(point3D_in_cam[2])};
    Eigen::Matrix<Jet, 2, 1> log_map;
    sphera::AngularLogResidual(observed_ray, point, log_map.data());
    const Eigen::Matrix<Jet, 2, 2> w =
        AngularWeightAt<CameraModel>(weight, params, pixel, observed_ray);
    const Eigen::Matrix<Jet, 2, 1> residual = w * log_map;
    for (int row = 0; row < 2; ++row) {
      residuals[row] = residual(row).a;
      for (int i = 0; i < kNumParams; ++i) {
        J_params[row * kNumParams + i] = residual(row).v[i];
      }
    }
    if (J_point_in_cam != nullptr) {
      const double ray_value[3] = {
          observed_ray[0].a, observed_ray[1].a, observed_ray[2].a};
      Eigen::Vector2d log_value;
      Eigen::Matrix<double, 2, 3, Eigen::RowMajor> J_log_map;
      sphera::AngularLogResidualWithJacobian(
          ray_value, point3D_in_cam, log_value.data(), J_log_map.data());
      Eigen::Matrix2d w_value;
      w_value << w(0, 0).a, w(0, 1).a, w(1, 0).a, w(1, 1).a;
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> J_map(
          J_point_in_cam);
      J_map = w_value * J_log_map;
    }
    return true;
  }
}

// AngularReprojErrorCostFunctor with analytic Jacobians: what bundle
// adjustment uses for a spherical camera (upstream's analytic pixel cost
// functions are its counterpart), the autodiff functor being the reference
// it is tested against.
template <typename CameraModel>
class AngularReprojErrorCostFunction
    : public ceres::SizedCostFunction<2, 3, 7, CameraModel::num_params> {
 public:
  AngularReprojErrorCostFunction(const double* camera_params,
                                 const Eigen::Vector2d& point2D)
      : point2D_(point2D),
        weight_(AngularResidualWeight<CameraModel>(camera_params, point2D)) {}

  static ceres::CostFunction* Create(const double* camera_params,
                                     const Eigen::Vector2d& point2D) {
    return new AngularReprojErrorCostFunction(camera_params, point2D);
  }

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override {
    const double* point3D_in_world = parameters[0];
    const double* cam_from_world = parameters[1];
    double* J_point = jacobians ? jacobians[0] : nullptr;
    double* J_pose = jacobians ? jacobians[1] : nullptr;
    double* J_params = jacobians ? jacobians[2] : nullptr;

    Eigen::Matrix<double, 3, 4, Eigen::RowMajor> J_rotated_quat;
    const Eigen::Vector3d point3D_in_cam =
        QuaternionRotatePointWithJac(cam_from_world,
                                     point3D_in_world,
                                     J_pose ? J_rotated_quat.data() : nullptr) +
        Eigen::Map<const Eigen::Vector3d>(cam_from_world + 4);
    Eigen::Matrix<double, 2, 3, Eigen::RowMajor> J_in_cam;
    if (!AngularReprojResidualWithJacobians<CameraModel>(
            parameters[2],
            point2D_,
            point3D_in_cam.data(),
            weight_,
            residuals,
            (J_point || J_pose) ? J_in_cam.data() : nullptr,
            J_params)) {
      return false;
    }
    if (J_point) {
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> J_point_mat(
          J_point);
      J_point_mat =
          J_in_cam *
          EigenQuaternionMap<double>(cam_from_world).toRotationMatrix();
    }
    if (J_pose) {
      Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> J_pose_mat(
          J_pose);
      J_pose_mat.leftCols<4>() = J_in_cam * J_rotated_quat;
      J_pose_mat.rightCols<3>() = J_in_cam;
    }
    return true;
  }

 private:
  const Eigen::Vector2d point2D_;
  const AngularWeight weight_;
};

// The same with a constant pose (upstream's
// ReprojErrorConstantPoseCostFunctor), analytic only.
template <typename CameraModel>
class AngularReprojErrorConstantPoseCostFunction
    : public ceres::SizedCostFunction<2, 3, CameraModel::num_params> {
 public:
  AngularReprojErrorConstantPoseCostFunction(const double* camera_params,
                                             const Eigen::Vector2d& point2D,
                                             const Rigid3d& cam_from_world)
      : point2D_(point2D),
        weight_(AngularResidualWeight<CameraModel>(camera_params, point2D)),
        cam_from_world_rotation_(cam_from_world.rotation().toRotationMatrix()),
        cam_from_world_translation_(cam_from_world.translation()) {}

  static ceres::CostFunction* Create(const double* camera_params,
                                     const Eigen::Vector2d& point2D,
                                     const Rigid3d& cam_from_world) {
    return new AngularReprojErrorConstantPoseCostFunction(
        camera_params, point2D, cam_from_world);
  }

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override {
    double* J_point = jacobians ? jacobians[0] : nullptr;
    double* J_params = jacobians ? jacobians[1] : nullptr;
    const Eigen::Vector3d point3D_in_cam =
        cam_from_world_rotation_ *
            Eigen::Map<const Eigen::Vector3d>(parameters[0]) +
        cam_from_world_translation_;
    Eigen::Matrix<double, 2, 3, Eigen::RowMajor> J_in_cam;
    if (!AngularReprojResidualWithJacobians<CameraModel>(
            parameters[1],
            point2D_,
            point3D_in_cam.data(),
            weight_,
            residuals,
            J_point ? J_in_cam.data() : nullptr,
            J_params)) {
      return false;
    }
    if (J_point) {
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> J_point_mat(
          J_point);
      J_point_mat = J_in_cam * cam_from_world_rotation_;
    }
    return true;
  }

 private:
  const Eigen::Vector2d point2D_;
  const AngularWeight weight_;
  const Eigen::Matrix3d cam_from_world_rotation_;
  const Eigen::Vector3d cam_from_world_translation_;
};

template <typename CameraModel>
class AngularReprojErrorCostFunctor
    : public AutoDiffCostFunctor<AngularReprojErrorCostFunctor<CameraModel>,
                                 2,
                                 3,
                                 7,
                                 CameraModel::num_params> {
 public:
  AngularReprojErrorCostFunctor(const double* camera_params,
                                const Eigen::Vector2d& point2D)
      : point2D_(point2D),
        weight_(AngularResidualWeight<CameraModel>(camera_params, point2D)) {}

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
        camera_params, point2D_, point3D_in_cam, weight_, residuals);
  }

 private:
  const Eigen::Vector2d point2D_;
  const AngularWeight weight_;
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
      const double* camera_params,
      const Eigen::Vector2d& point2D,
      const Eigen::Vector3d& point3D_in_world)
      : point3D_in_world_(point3D_in_world),
        reproj_cost_(camera_params, point2D) {}

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

// The residual of a lens of a rig with analytic derivatives: the point goes
// through rig_from_world, then cam_from_rig, and the chain rule joins the
// rotations' Jacobians to the residual's. Any Jacobian may be nullptr (a
// constant cam_from_rig passes none for it).
template <typename CameraModel>
bool AngularRigResidualWithJacobians(const Eigen::Vector2d& point2D,
                                     const AngularWeight& weight,
                                     const double* point3D_in_world,
                                     const double* cam_from_rig,
                                     const double* rig_from_world,
                                     const double* camera_params,
                                     double* residuals,
                                     double* J_point,
                                     double* J_cam_from_rig,
                                     double* J_rig_from_world,
                                     double* J_params) {
  Eigen::Matrix<double, 3, 4, Eigen::RowMajor> J_rig_quat;
  Eigen::Matrix<double, 3, 4, Eigen::RowMajor> J_cam_quat;
  const Eigen::Vector3d point3D_in_rig =
      QuaternionRotatePointWithJac(
          rig_from_world,
          point3D_in_world,
          J_rig_from_world ? J_rig_quat.data() : nullptr) +
      Eigen::Map<const Eigen::Vector3d>(rig_from_world + 4);
  const Eigen::Vector3d point3D_in_cam =
      QuaternionRotatePointWithJac(cam_from_rig,
                                   point3D_in_rig.data(),
                                   J_cam_from_rig ? J_cam_quat.data()
                                                  : nullptr) +
      Eigen::Map<const Eigen::Vector3d>(cam_from_rig + 4);
  const bool geometry = J_point || J_cam_from_rig || J_rig_from_world;
  Eigen::Matrix<double, 2, 3, Eigen::RowMajor> J_in_cam;
  if (!AngularReprojResidualWithJacobians<CameraModel>(
          camera_params,
          point2D,
          point3D_in_cam.data(),
          weight,
          residuals,
          geometry ? J_in_cam.data() : nullptr,
          J_params)) {
    return false;
  }
  if (!geometry) {
    return true;
  }
  using Jacobian2x7 = Eigen::Matrix<double, 2, 7, Eigen::RowMajor>;
  if (J_cam_from_rig) {
    Eigen::Map<Jacobian2x7> J(J_cam_from_rig);
    J.leftCols<4>() = J_in_cam * J_cam_quat;
    J.rightCols<3>() = J_in_cam;
  }
  const Eigen::Matrix<double, 2, 3> J_in_rig =
      J_in_cam * EigenQuaternionMap<double>(cam_from_rig).toRotationMatrix();
  if (J_rig_from_world) {
    Eigen::Map<Jacobian2x7> J(J_rig_from_world);
    J.leftCols<4>() = J_in_rig * J_rig_quat;
    J.rightCols<3>() = J_in_rig;
  }
  if (J_point) {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> J(J_point);
    J = J_in_rig *
        EigenQuaternionMap<double>(rig_from_world).toRotationMatrix();
  }
  return true;
}

// The angular residual of a lens of a rig with analytic Jacobians: what
// bundle adjustment uses for a lens of a rig (every observation of a
// non-reference lens); the tests hold it against autodiff of the same
// residual.
template <typename CameraModel>
class AngularRigReprojErrorCostFunction
    : public ceres::
          SizedCostFunction<2, 3, 7, 7, CameraModel::num_params> {
 public:
  AngularRigReprojErrorCostFunction(const double* camera_params,
                                    const Eigen::Vector2d& point2D)
      : point2D_(point2D),
        weight_(AngularResidualWeight<CameraModel>(camera_params, point2D)) {}

  static ceres::CostFunction* Create(const double* camera_params,
                                     const Eigen::Vector2d& point2D) {
    return new AngularRigReprojErrorCostFunction(camera_params, point2D);
  }

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override {
    return AngularRigResidualWithJacobians<CameraModel>(
        point2D_,
        weight_,
        parameters[0],
        parameters[1],
        parameters[2],
        parameters[3],
        residuals,
        jacobians ? jacobians[0] : nullptr,
        jacobians ? jacobians[1] : nullptr,
        jacobians ? jacobians[2] : nullptr,
        jacobians ? jacobians[3] : nullptr);
  }

 private:
  const Eigen::Vector2d point2D_;
  const AngularWeight weight_;
};

// The same with a constant cam_from_rig (upstream's
// RigReprojErrorConstantRigCostFunctor), analytic only.
template <typename CameraModel>
class AngularRigReprojErrorConstantRigCostFunction
    : public ceres::SizedCostFunction<2, 3, 7, CameraModel::num_params> {
 public:
  AngularRigReprojErrorConstantRigCostFunction(const double* camera_params,
                                               const Eigen::Vector2d& point2D,
                                               const Rigid3d& cam_from_rig)
      : point2D_(point2D),
        weight_(AngularResidualWeight<CameraModel>(camera_params, point2D)),
        cam_from_rig_(cam_from_rig.params) {}

  static ceres::CostFunction* Create(const double* camera_params,
                                     const Eigen::Vector2d& point2D,
                                     const Rigid3d& cam_from_rig) {
    return new AngularRigReprojErrorConstantRigCostFunction(
        camera_params, point2D, cam_from_rig);
  }

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override {
    return AngularRigResidualWithJacobians<CameraModel>(
        point2D_,
        weight_,
        parameters[0],
        cam_from_rig_.data(),
        parameters[1],
        parameters[2],
        residuals,
        jacobians ? jacobians[0] : nullptr,
        nullptr,
        jacobians ? jacobians[1] : nullptr,
        jacobians ? jacobians[2] : nullptr);
  }

 private:
  const Eigen::Vector2d point2D_;
  const AngularWeight weight_;
  const Eigen::Matrix<double, 7, 1> cam_from_rig_;
};

// The angular cost that takes the place of an upstream pixel functor.
template <template <typename> class PixelFunctor>
struct AngularFunctorOf;
template <>
struct AngularFunctorOf<ReprojErrorCostFunctor> {
  template <typename M>
  using type = AngularReprojErrorCostFunction<M>;
};
template <>
struct AngularFunctorOf<ReprojErrorConstantPoseCostFunctor> {
  template <typename M>
  using type = AngularReprojErrorConstantPoseCostFunction<M>;
};
template <>
struct AngularFunctorOf<ReprojErrorConstantPoint3DCostFunctor> {
  template <typename M>
  using type = AngularReprojErrorConstantPoint3DCostFunctor<M>;
};
template <>
struct AngularFunctorOf<RigReprojErrorCostFunctor> {
  template <typename M>
  using type = AngularRigReprojErrorCostFunction<M>;
};
template <>
struct AngularFunctorOf<RigReprojErrorConstantRigCostFunctor> {
  template <typename M>
  using type = AngularRigReprojErrorConstantRigCostFunction<M>;
};

// The pixel cost of upstream's CameraModel exactly as CreateCameraCostFunction
// makes it: analytic where upstream has it, else the functor.
template <template <typename> class PixelFunctor,
          typename CameraModel,
          typename... Args>
ceres::CostFunction* CreateUpstreamModelCostFunction(Args&&... args) {
  if constexpr (std::is_same_v<PixelFunctor<CameraModel>,
                               ReprojErrorCostFunctor<CameraModel>> &&
                CameraModel::has_img_from_cam_with_jac) {
    return CreateAnalyticalReprojErrorCostFunction<CameraModel>(
        std::forward<Args>(args)...);
  } else if constexpr (std::is_same_v<
                           PixelFunctor<CameraModel>,
                           ReprojErrorConstantPoseCostFunctor<CameraModel>> &&
                       CameraModel::has_img_from_cam_with_jac) {
    return CreateAnalyticalReprojErrorConstantPoseCostFunction<CameraModel>(
        std::forward<Args>(args)...);
  } else {
    return PixelFunctor<CameraModel>::Create(std::forward<Args>(args)...);
  }
}

// The pixel cost of upstream's model of the same id as CAMERA's whole-field
// model, for a camera whose image lies in front of its image plane
// (camera_category.h): the same projection there, with upstream's own
// Jacobians.
template <template <typename> class PixelFunctor, typename... Args>
ceres::CostFunction* CreateInFrontCameraCostFunction(const Camera& camera,
                                                     Args&&... args) {
  switch (camera.model_id) {
    case OpenCVFisheyeCameraModel::model_id:
      return CreateUpstreamModelCostFunction<PixelFunctor,
                                             OpenCVFisheyeCameraModel>(
          std::forward<Args>(args)...);
    case ThinPrismFisheyeCameraModel::model_id:
      return CreateUpstreamModelCostFunction<PixelFunctor,
                                             ThinPrismFisheyeCameraModel>(
          std::forward<Args>(args)...);
    case EUCMCameraModel::model_id:
      return CreateUpstreamModelCostFunction<PixelFunctor, EUCMCameraModel>(
          std::forward<Args>(args)...);
    default:
      return CreateCameraCostFunction<PixelFunctor>(
          camera.model_id, std::forward<Args>(args)...);
  }
}

// CreateCameraCostFunction<PixelFunctor>, with the angular residual in its
// place for a spherical camera when `residual` is ANGULAR, in the pixels of
// CAMERA's parameters as they are now. A whole-field camera whose image lies
// in front of its image plane is not spherical and gets upstream's cost.
template <template <typename> class PixelFunctor, typename... Args>
ceres::CostFunction* CreateSphereCameraCostFunction(
    const SphereResidualType residual, const Camera& camera, Args&&... args) {
  if (residual == SphereResidualType::ANGULAR && camera.IsSpherical()) {
    return CreateCameraCostFunction<
        AngularFunctorOf<PixelFunctor>::template type>(
        camera.model_id, camera.params.data(), std::forward<Args>(args)...);
  }
  if (InFrontCameraCategory(camera) != UpstreamCategory::kNone) {
    return CreateInFrontCameraCostFunction<PixelFunctor>(
        camera, std::forward<Args>(args)...);
  }
  return CreateCameraCostFunction<PixelFunctor>(camera.model_id,
                                                std::forward<Args>(args)...);
}

}  // namespace colmap
