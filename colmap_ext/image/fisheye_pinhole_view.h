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
  // The fisheye's resolution at the principal point (pixels per radian, the
  // inverse of the model's PixelToAngle in camera_models/), as
  // sphere_undistorter's faces use it.
  const double focal = 1.0 / camera.CamFromImgThreshold(1.0);
  const double cx = camera.PrincipalPointX();
  const double cy = camera.PrincipalPointY();
  const double w = static_cast<double>(camera.width);
  const double h = static_cast<double>(camera.height);
  // Widened (a longer focal length) until the farthest image edge along an
  // axis is within the cap.
  const double view_focal =
      std::max(focal, std::max({cx, w - cx, cy, h - cy}) / cap);

  Camera view;
  view.camera_id = camera.camera_id;
  view.model_id = PinholeCameraModel::model_id;
  view.width = camera.width;
  view.height = camera.height;
  view.params = {view_focal, view_focal, cx, cy};
  return view;
}

}  // namespace colmap
