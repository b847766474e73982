#include "colmap_ext/scene/sphere_reprojection_error.h"

#include "colmap_ext/estimators/angular_pixel_residual.h"

namespace colmap {
namespace {

template <typename CameraModel>
std::optional<double> SquaredErrorOf(const Camera& camera,
                                     const Eigen::Vector2d& point2D,
                                     const Eigen::Vector3d& point3D_in_cam) {
  if (camera.params.size() != CameraModel::num_params) {
    return std::nullopt;
  }
  const double* params = camera.params.data();
  Eigen::Vector2d residual;
  if (!AngularReprojResidual<CameraModel>(
          params,
          point2D,
          point3D_in_cam,
          AngularResidualWeight<CameraModel>(params, point2D),
          residual.data())) {
    return std::nullopt;
  }
  return residual.squaredNorm();
}

}  // namespace

std::optional<double> SquaredSphereReprojectionError(
    const Camera& camera,
    const Eigen::Vector2d& point2D,
    const Eigen::Vector3d& point3D_in_cam) {
  switch (static_cast<int>(camera.model_id)) {
#define CAMERA_MODEL_CASE(CameraModel)          \
  case static_cast<int>(CameraModel::model_id): \
    return SquaredErrorOf<CameraModel>(camera, point2D, point3D_in_cam);
    CAMERA_MODEL_CASES
#undef CAMERA_MODEL_CASE
    default:
      return std::nullopt;
  }
}

}  // namespace colmap
