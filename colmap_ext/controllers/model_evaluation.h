// Scores a reconstruction against ground truth (`colmap model_evaluator`):
// registered images, pose errors after alignment, angular reprojection error
// and, with sphera_render's range maps, the 3D point error.
#pragma once

#include "colmap/geometry/sim3.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/util/enum_utils.h"

#include <string>
#include <vector>

namespace colmap {

// How the reconstruction is aligned to the ground truth before its pose errors
// are measured. Both start from a robust similarity on the camera centres
// (RANSAC, inliers within max_proj_center_error), then refine on its inliers:
//   CENTERS       least-squares similarity of the inlier centres (Umeyama
//                 1991), as the SPHERA paper and most published evaluations;
//   ORIENTATIONS  rotation from the camera orientations (geodesic median of
//                 R_gt^T R), scale and translation by least squares on the
//                 inlier centres with that rotation.
MAKE_ENUM_CLASS_OVERLOAD_STREAM(ModelAlignment, 0, CENTERS, ORIENTATIONS);

struct ModelEvaluationOptions {
  ModelAlignment alignment = ModelAlignment::CENTERS;
  // Inlier threshold of the robust similarity on camera centres, in ground
  // truth units, >= 0; 0 picks 5% of the largest distance between
  // ground-truth camera centres.
  double max_proj_center_error = 0;
  // Folder with the ground-truth range maps NAME.depth.bin (sphera_render's
  // format); empty skips the 3D point error.
  std::string depth_path;

  // Empty, or why an option is out of its range (naming the option).
  std::string Check() const;
};

struct ImageEvaluation {
  std::string name;
  bool registered = false;
  double rotation_error_deg = -1;
  double position_error = -1;
  double position_error_normalized = -1;
};

struct CameraEvaluation {
  camera_t camera_id = kInvalidCameraId;
  std::string model_name;
  size_t num_observations = 0;
  double mean_angular_error_rad = 0;
  double mean_angular_error_px = 0;
};

struct ModelEvaluation {
  ModelAlignment alignment = ModelAlignment::CENTERS;
  // The similarity that maps the reconstruction onto the ground truth.
  Sim3d gt_from_reconstruction;
  size_t num_gt_images = 0;
  size_t num_registered = 0;
  size_t num_points3D = 0;
  double closest_pair_baseline = 0;
  double mean_rotation_error_deg = 0;
  double max_rotation_error_deg = 0;
  double mean_position_error = 0;
  double max_position_error = 0;
  double mean_position_error_normalized = 0;
  size_t num_observations = 0;
  double mean_angular_error_rad = 0;
  double mean_angular_error_px = 0;
  // Distance of each estimated point (aligned) to the ground-truth surface
  // along its observed ray; -1 when no depth was given.
  size_t num_points_with_depth = 0;
  double mean_point_error = -1;
  double median_point_error = -1;
  std::vector<ImageEvaluation> images;
  std::vector<CameraEvaluation> cameras;
};

// Aligns `reconstruction` to `ground_truth` as options.alignment says (no
// reprojection involved, so any camera model works) and measures the errors.
// Throws std::invalid_argument with a message when the models cannot be
// compared (fewer than 3 common registered images, no alignment).
ModelEvaluation EvaluateModel(const Reconstruction& ground_truth,
                              const Reconstruction& reconstruction,
                              const ModelEvaluationOptions& options);

// "centers" or "orientations", as the command line and the outputs name it.
std::string AlignmentName(ModelAlignment alignment);

std::string ModelEvaluationToJson(const ModelEvaluation& evaluation);

}  // namespace colmap
