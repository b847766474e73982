// Which of COLMAP's camera categories a camera of a whole-field model falls
// in. SPHERA's OPENCV_FISHEYE, THIN_PRISM_FISHEYE and EUCM take upstream's ids
// and reach behind the image plane, so in COLMAP's taxonomy they are
// spherical models (rays on the unit sphere, the angular residual). A camera
// of one of them whose image circle sees only rays in front of its image
// plane (a lens under 180°) is what upstream's model of the same id covers:
// it then takes that model's category, and registration, triangulation,
// two-view geometry, bundle adjustment and undistortion treat it exactly as
// upstream does (Camera::IsSpherical and the other category predicates ask
// InFrontCameraCategory). A full-frame fisheye whose corners alone see
// beyond 90° is upstream's camera too, and those corners are lost as
// upstream loses them.
#pragma once

#include "colmap/scene/camera.h"

namespace colmap {

// The category of upstream's model of the same id (OPENCV_FISHEYE and
// THIN_PRISM_FISHEYE are perspective fisheye models there, EUCM a
// perspective pinhole one).
enum class UpstreamCategory { kNone, kPerspectiveFisheye, kPerspectivePinhole };

// For CAMERA: when it is of one of the whole-field models above, the image
// circle its frame shows (the disc about the principal point that reaches the
// frame's farthest edge: a fisheye's circle, whole or cropped by two edges,
// lies inside it) sees only rays in front of its image plane
// (FieldInFrontOfImagePlane of camera_models/), and its intrinsics are the
// user's (has_prior_focal_length: a lens calibrated with camera_params; a focal
// length the image reader guessed says nothing of the lens's field, and
// upstream cannot map fisheye images without one), the category upstream
// gives it; kNone for every other camera, for parameters of the wrong count
// and for an image without a size.
UpstreamCategory InFrontCameraCategory(const Camera& camera);

}  // namespace colmap
