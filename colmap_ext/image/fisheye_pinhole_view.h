// The perspective view that `image_undistorter` makes of a spherical fisheye
// image (EUCM, UNIFIED_OMNI, DOUBLE_SPHERE: lenses up to and beyond 180
// degrees). COLMAP's own rule (fit the pinhole to the distorted image's
// border) has nothing to fit when the border sees rays behind the lens plane,
// so these cameras get one PINHOLE view along the optical axis instead: same
// image size and principal point, the fisheye's own resolution at its centre,
// widened only as far as needed to keep the view within a half-angle cap
// along the image axes. The full field of view goes to MVS through
// `sphere_undistorter` (cube faces). EQUIRECTANGULAR has no optical axis and
// stays as upstream handles it.
#pragma once

#include "colmap/scene/camera.h"
#include "colmap/sensor/models.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include <Eigen/Core>

namespace colmap {

// True for spherical models with a focal length (SPHERA's fisheye models).
inline bool HasFisheyePinholeView(const Camera& camera) {
  return camera.IsSpherical() && !camera.FocalLengthIdxs().empty();
}

// Default half-angle cap of the view along the image axes: 60 degrees (a
// 120 degree view), as tan(60 degrees).
constexpr double kFisheyePinholeViewMaxNormalized = 1.7320508075688772;

// PINHOLE camera of the view; `max_normalized` > 0 is the largest normalized
// image coordinate (tan of the half-angle) the view reaches along its axes,
// otherwise kFisheyePinholeViewMaxNormalized. Requires
// HasFisheyePinholeView(camera).
inline Camera FisheyePinholeView(const Camera& camera, double max_normalized) {
  const double cap =
      max_normalized > 0 ? max_normalized : kFisheyePinholeViewMaxNormalized;
  // The fisheye's magnification at the principal point, pixels per unit of
  // normalized coordinate, from its own projection.
  constexpr double kStep = 1e-6;
  const std::optional<Eigen::Vector2d> center =
      camera.ImgFromCam(Eigen::Vector3d(0, 0, 1));
  const std::optional<Eigen::Vector2d> along_x =
      camera.ImgFromCam(Eigen::Vector3d(kStep, 0, 1));
  const std::optional<Eigen::Vector2d> along_y =
      camera.ImgFromCam(Eigen::Vector3d(0, kStep, 1));
  double fx = camera.FocalLengthX();
  double fy = camera.FocalLengthY();
  if (center && along_x && along_y) {
    fx = (along_x->x() - center->x()) / kStep;
    fy = (along_y->y() - center->y()) / kStep;
  }
  const double cx = camera.PrincipalPointX();
  const double cy = camera.PrincipalPointY();
  const double half_width =
      std::max(cx, static_cast<double>(camera.width) - cx);
  const double half_height =
      std::max(cy, static_cast<double>(camera.height) - cy);
  const double scale =
      std::max({1.0, half_width / (cap * fx), half_height / (cap * fy)});

  Camera view;
  view.camera_id = camera.camera_id;
  view.model_id = PinholeCameraModel::model_id;
  view.width = camera.width;
  view.height = camera.height;
  view.params = {scale * fx, scale * fy, cx, cy};
  return view;
}

}  // namespace colmap
