// `colmap sphere_bundle_adjuster`: bundle adjustment of an existing model,
// SPHERA's camera-only BA (Gava & Stricker 2015, Eq. 6/7) or COLMAP's full BA,
// with the angular or the pixel residual.
//
//   colmap sphere_bundle_adjuster --input_path MODEL --output_path OUT
//       [--mode camera_only|full] [--tau_px 2] [--max_iterations 20]
//       [--refine_intrinsics 0|1] [--residual angular|pixel]
//       [--loss none|cauchy] [--loss_scale_px 1]
//       [--min_observations_per_image 6]
//
// camera_only: sphera::CameraOnlyBundleAdjustment (estimators/
//   camera_only_bundle_adjustment.h) on the rays Camera::CamRayFromImg of the
//   observations; tau per camera = tau_px * Camera::CamRayFromImgThreshold(1).
//   The poses are refined, the points are re-triangulated, and only the
//   reliable points (every observation within tau) are written. Gauge: the
//   first registered image (smallest id) is fixed and the distance between
//   the centres of the first two is kept. --max_iterations counts the outer
//   iterations (re-triangulate, select, pose step). With --refine_intrinsics 1
//   the intrinsics of the cameras that have focal parameters (e.g. the
//   perspective cameras of a hybrid set) are refined after every pose step on
//   the fixed reliable points with COLMAP's ReprojErrorConstantPoint3D cost
//   (angular for the sphere models); a model's fixed parameters
//   (EQUIRECTANGULAR w, h) and principal points stay constant.
// full: COLMAP's BundleAdjuster (poses and points; for the sphere models its
//   residual is already the exact angle, scaled to pixels), gauge as COLMAP:
//   first image fixed and one translation coordinate of the second.
//   --max_iterations is the number of Ceres iterations (at least 100).
// --residual pixel (full mode only): the same problem with the pixel
//   reprojection residual ImgFromCam(R X + t) - x of every model; for
//   EQUIRECTANGULAR the x residual is wrapped into [-w/2, w/2] across the
//   seam. For comparisons with the angular residual (the paper's Table 1).
//
// Bad input (tau_px <= 0 or so small that no reliable point remains, too few
// observations per image, degenerate geometry, unreadable model) is reported
// with the parameter named and a non-zero exit; OUT is written only when the
// refinement succeeded.
#pragma once

#include "colmap/scene/reconstruction.h"

#include <string>

namespace colmap {

struct SphereBundleAdjusterOptions {
  std::string mode = "camera_only";  // camera_only | full
  double tau_px = 2.0;
  int max_iterations = 20;
  bool refine_intrinsics = false;
  std::string residual = "angular";  // angular | pixel
  std::string loss = "none";         // none | cauchy
  double loss_scale_px = 1.0;
  int min_observations_per_image = 6;
};

struct SphereBundleAdjusterSummary {
  int iterations = 0;
  size_t num_points_before = 0;
  size_t num_points_after = 0;  // reliable points for camera_only
  size_t num_observations_before = 0;
  size_t num_observations_after = 0;
  double mean_error_before_rad = 0;  // over all observations of the points
  double mean_error_before_px = 0;
  double mean_error_after_rad = 0;
  double mean_error_after_px = 0;
  double seconds = 0;
};

// Mean angle between the observed rays (Camera::CamRayFromImg) and the
// directions of the points, over every observation of every 3D point, in
// radians and in pixel equivalents (per camera radians per pixel).
void MeanAngularError(const Reconstruction& reconstruction,
                      size_t* num_observations, double* mean_rad,
                      double* mean_px);

// Runs the adjustment in place. Returns false with a message (naming the
// parameter or image) on bad options, bad input or failure; the
// reconstruction is then unchanged.
bool SphereBundleAdjust(const SphereBundleAdjusterOptions& options,
                        Reconstruction* reconstruction,
                        SphereBundleAdjusterSummary* summary,
                        std::string* error);

// The mapper's option Mapper.camera_only_ba_tau_px: camera-only adjustment
// of a finished reconstruction in place, with a log line of what it did; on
// failure (e.g. tau below the noise floor) the reconstruction is kept as it
// was and a warning names the reason.
void RunCameraOnlyRefinement(double tau_px, Reconstruction* reconstruction);

int RunSphereBundleAdjuster(int argc, char** argv);

}  // namespace colmap
