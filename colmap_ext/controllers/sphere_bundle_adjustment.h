// Bundle adjustment of an existing model (`colmap sphere_bundle_adjuster`):
// SPHERA's camera-only BA (Gava & Stricker 2015, Eq. 6/7) or the full BA of
// poses and points, with the angular or the pixel residual.
//
// CAMERA_ONLY: sphera::CameraOnlyBundleAdjustment (estimators/
//   camera_only_bundle_adjustment.h) on the rays Camera::CamRayFromImg of the
//   observations; tau per camera = tau_px times the camera's radians per pixel
//   (Camera::CamFromImgThreshold(1)). The poses are refined, the points are
//   re-triangulated, and only the reliable points (every observation within
//   tau) are kept. Gauge: the first registered image (smallest id) is fixed
//   and the distance between the centres of the first two is kept.
//   max_iterations counts the outer iterations (re-triangulate, select, pose
//   step). Every registered frame must hold exactly one image (the poses are
//   per image; a rig's images would be moved apart). With refine_intrinsics
//   the intrinsics of the cameras that have focal parameters (e.g. the
//   perspective cameras of a hybrid set) are refined after every pose step on
//   the fixed reliable points, together with the poses of their images
//   (except the two gauge images), with bundle adjustment's residual
//   (angular for the spherical cameras); metadata parameters
//   (EQUIRECTANGULAR w, h) and principal points stay constant.
// FULL: COLMAP's own bundle adjuster (CreateDefaultBundleAdjuster) with
//   BundleAdjustmentOptions::sphere_residual: for the spherical cameras
//   (Camera::IsSpherical(): EQUIRECTANGULAR, EUCM, UNIFIED_OMNI,
//   DOUBLE_SPHERE) the exact angle between the observed ray and the point in
//   pixel equivalents (ANGULAR) or upstream's pixel residual, wrapped at the
//   EQUIRECTANGULAR seam (PIXEL); perspective cameras always take the pixel
//   residual. Gauge: the first image's frame fixed and one translation
//   coordinate of a second frame. max_iterations is the number of Ceres
//   iterations (at least 100). Rig extrinsics stay constant.
//
// Bad input (tau_px <= 0 or so small that no reliable point remains, too few
// observations per image, degenerate geometry, bad camera parameters) is
// reported with the option or image named; the reconstruction is then left as
// it was.
#pragma once

#include "colmap/scene/reconstruction.h"
#include "colmap/util/enum_utils.h"
#include "colmap_ext/estimators/sphere_residual_type.h"

#include <map>
#include <string>

namespace colmap {

MAKE_ENUM_CLASS_OVERLOAD_STREAM(SphereBundleAdjustmentMode, 0, CAMERA_ONLY,
                                FULL);
MAKE_ENUM_CLASS_OVERLOAD_STREAM(SphereBundleAdjustmentLoss, 0, NONE, CAUCHY);

// The command line takes every enum by its name in any letter case
// (OptionManager::AddDefaultEnumOption).
struct SphereBundleAdjustmentOptions {
  using Mode = SphereBundleAdjustmentMode;
  using Residual = SphereResidualType;
  using Loss = SphereBundleAdjustmentLoss;

  Mode mode = Mode::CAMERA_ONLY;
  double tau_px = 2.0;
  int max_iterations = 20;
  bool refine_intrinsics = false;
  Residual residual = Residual::ANGULAR;
  Loss loss = Loss::NONE;
  double loss_scale_px = 1.0;  // Cauchy scale [px]
  int min_observations_per_image = 6;

  // Empty string if the options are valid, else a message naming the option.
  std::string Check() const;
};

struct SphereBundleAdjustmentSummary {
  int iterations = 0;
  size_t num_points_before = 0;
  size_t num_points_after = 0;  // reliable points for CAMERA_ONLY
  size_t num_observations_before = 0;
  size_t num_observations_after = 0;
  double mean_error_before_rad = 0;  // over all observations of the points
  double mean_error_before_px = 0;
  double mean_error_after_rad = 0;
  double mean_error_after_px = 0;
  double seconds = 0;
};

// The angles between the observed rays (Camera::CamRayFromImg) and the
// directions of the points, over every observation of every 3D point in a
// registered image, summed per camera in radians and in pixel equivalents
// (the camera's radians per pixel, Camera::CamFromImgThreshold(1)).
struct AngularErrorSum {
  size_t num_observations = 0;
  double sum_rad = 0;
  double sum_px = 0;
};
std::map<camera_t, AngularErrorSum> AngularErrorsByCamera(
    const Reconstruction& reconstruction);

// Their mean over all cameras.
void MeanAngularError(const Reconstruction& reconstruction,
                      size_t* num_observations,
                      double* mean_rad,
                      double* mean_px);

// Runs the adjustment in place. Returns false with a message (naming the
// option or image) on bad options, bad input or failure; the reconstruction
// is then unchanged.
bool SphereBundleAdjust(const SphereBundleAdjustmentOptions& options,
                        Reconstruction* reconstruction,
                        SphereBundleAdjustmentSummary* summary,
                        std::string* error);

// The mapper's option camera_only_ba_tau_px: camera-only adjustment of a
// finished reconstruction in place, with a log line of what it did; on
// failure (e.g. tau below the noise floor) the reconstruction is kept as it
// was and a warning names the reason. Nothing when tau_px is not positive
// (the option's default, 0).
void RunCameraOnlyRefinement(double tau_px, Reconstruction* reconstruction);

}  // namespace colmap
