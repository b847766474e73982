// Reprojection errors and cheirality on rays, for every camera model.
//
// An observation is the unit ray r of its pixel (Camera::CamRayFromImg); a
// point X_cam in camera coordinates is in front of it when r . X_cam > 0 and
// its error is the geodesic angle atan2(|r x X_cam|, r . X_cam). For the
// reprojection-error filters of the mapper, which take thresholds in pixels,
// the angle is divided by the camera's radians per pixel
// (Camera::CamRayFromImgThreshold(1)).
#pragma once

#include "colmap/scene/camera.h"

#include <Eigen/Core>

namespace colmap {

// Geodesic angle in radians between the pixel's ray and the point; pi when the
// pixel has no ray.
double CalculateRayAngularError(const Eigen::Vector2d& point2D,
                                const Eigen::Vector3d& point3D_in_cam,
                                const Camera& camera);

// Squared angular error in pixel equivalents; max double when the point lies
// behind the ray (angle >= 90°) or the pixel has no ray.
double CalculateSquaredRayReprojectionError(
    const Eigen::Vector2d& point2D,
    const Eigen::Vector3d& point3D_in_cam,
    const Camera& camera);

// Cheirality on the sphere: ray . X_cam > 0.
bool HasPointPositiveRayDepth(const Eigen::Vector2d& point2D,
                              const Eigen::Vector3d& point3D_in_cam,
                              const Camera& camera);

}  // namespace colmap
