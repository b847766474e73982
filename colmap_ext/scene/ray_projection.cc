#include "colmap_ext/scene/ray_projection.h"

#include <cmath>
#include <limits>

namespace colmap {
namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

double CalculateRayAngularError(const Eigen::Vector2d& point2D,
                                const Eigen::Vector3d& point3D_in_cam,
                                const Camera& camera) {
  Eigen::Vector3d ray_in_cam;
  if (!camera.CamRayFromImg(point2D, &ray_in_cam)) {
    return kPi;
  }
  return std::atan2(ray_in_cam.cross(point3D_in_cam).norm(),
                    ray_in_cam.dot(point3D_in_cam));
}

double CalculateSquaredRayReprojectionError(
    const Eigen::Vector2d& point2D,
    const Eigen::Vector3d& point3D_in_cam,
    const Camera& camera) {
  const double angle = CalculateRayAngularError(point2D, point3D_in_cam, camera);
  if (!(angle < kPi / 2)) {
    return std::numeric_limits<double>::max();
  }
  const double error_px = angle / camera.CamRayFromImgThreshold(1.0);
  return error_px * error_px;
}

bool HasPointPositiveRayDepth(const Eigen::Vector2d& point2D,
                              const Eigen::Vector3d& point3D_in_cam,
                              const Camera& camera) {
  Eigen::Vector3d ray_in_cam;
  return camera.CamRayFromImg(point2D, &ray_in_cam) &&
         ray_in_cam.dot(point3D_in_cam) >
             std::numeric_limits<double>::epsilon() * point3D_in_cam.norm();
}

}  // namespace colmap
