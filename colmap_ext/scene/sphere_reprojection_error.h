// The reprojection error of an observation of a spherical camera as bundle
// adjustment measures it: the angle between the observed ray and the
// point's direction, taken to pixels by the camera's own derivative at the
// observed pixel (estimators/angular_pixel_residual.h). COLMAP filters
// observations, triangulates and reports its errors by this number, so an
// observation that bundle adjustment sees 4 pixels off is not kept by a
// filter at 4 pixels that would see it at 2.3: a 200-degree lens has 1.7
// times as many pixels per radian along its rim as on its axis, which one
// scale for the whole image (the axis's) would miss. EQUIRECTANGULAR keeps
// its one scale, W / 2pi, as bundle adjustment does.
#pragma once

#include "colmap/scene/camera.h"

#include <optional>

#include <Eigen/Core>

namespace colmap {

// The squared error, in CAMERA's pixels, of the observation at POINT2D of a
// point at POINT3D_IN_CAM in the camera's frame. None for a camera without
// the angular residual (the perspective models) or a pixel without a ray.
std::optional<double> SquaredSphereReprojectionError(
    const Camera& camera,
    const Eigen::Vector2d& point2D,
    const Eigen::Vector3d& point3D_in_cam);

}  // namespace colmap
