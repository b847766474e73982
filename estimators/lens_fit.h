// SPHERA estimators: calibration of one lens from a planar target (a
// checkerboard seen in several images), for any camera model of
// camera_models/registry.h.
//
// Problem
// -------
// Unknowns: the model's intrinsics p (all of them except the model's
// kFixedParamsIdxs; the principal point is free) and one pose cam_from_board_i
// per board image (angle-axis and translation). Residual of a board point X
// observed at pixel x in image i:
//   r = ImageFromRay(p, normalize(R_i X + t_i)) - x      [pixels]
// minimised in least squares (no robust loss: every detected corner counts,
// so the RMS is that of all corners). The reprojection error is in pixels
// because the corners are measured in pixels and every model is compared on
// the same scale. A board point the model does not see from a pose ("not
// visible") makes that trial step invalid, so the solver shortens it.
//
// Initialisation
// --------------
// A fit starts several times and keeps the start with the smallest final
// RMS. Each start has a focal length f, from the farthest corner's radius
// r_max around the image centre seen at a half angle theta_0 of 45° to 120°
// (f = r_max / theta_0), and one of two intrinsics:
//   - the model's own InitialParams(f, w, h);
//   - the model fitted (intrinsics only) to the equidistant lens r = f theta
//     over the rays up to theta_0, which gives every model a wide-angle start
//     (e.g. OCAM's InitialParams is a pinhole that sees no ray beyond 90°).
// The board poses come from a homography on the rays lifted with the start's
// intrinsics (DLT on ray x (H (X, Y, 1)) = 0; its sign puts the board in front
// along the rays, so boards beyond 90° from the axis are handled). Then the
// poses are refined with the intrinsics held, and finally everything is
// refined together; each stage uses the corners visible at its start, and the
// final stage is repeated once with all corners the fitted model sees.
//
// The board points must lie in the plane z = 0 of the board (a checkerboard).
//
// No COLMAP headers: Eigen, Ceres and camera_models/ only.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sphera {

// One detected board corner: the board image it was found in (0-based), the
// corner on the board (board frame, z = 0) and its pixel in COLMAP's
// convention (the centre of the upper-left pixel is (0.5, 0.5)).
struct BoardObservation {
  int image_index = 0;
  Eigen::Vector3d point_in_board = Eigen::Vector3d::Zero();
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
};

struct LensFitOptions {
  // Half angles (degrees) at which the farthest corner is assumed for the
  // starting focal lengths; one start per angle and initialisation kind.
  std::vector<double> initial_half_angles_deg = {45, 60, 75, 90, 105, 120};
  // Ceres iterations of each refinement stage.
  int max_num_iterations = 200;
  // An image needs at least this many corners (a homography needs 4).
  int min_observations_per_image = 6;

  // Throws std::invalid_argument naming the bad option.
  void Check() const;
};

enum class LensFitStatus {
  kSuccess,        // the solver converged and CheckParams accepts the params
  kNoConvergence,  // the solver stopped at its iteration limit
  kInvalidParams,  // converged, but CheckParams refuses the fitted params
  kFailure,        // no start gave a usable fit (message says why)
};

const char* LensFitStatusName(LensFitStatus status);

struct LensFitResult {
  int model_id = -1;
  std::string model_name;
  LensFitStatus status = LensFitStatus::kFailure;
  std::string message;  // CheckParams' message, or why the fit failed
  std::vector<double> params;
  // Indexed like the input's image indices; images with too few corners keep
  // the identity and are listed in skipped_images.
  std::vector<Eigen::Quaterniond> cam_from_board_rotations;
  std::vector<Eigen::Vector3d> cam_from_board_translations;
  std::vector<int> skipped_images;
  // Over the corners the fitted model sees (the RMS is over both pixel axes
  // together: sqrt(mean |r|²)); corners it does not see are counted apart.
  double rms_error_px = 0;
  double max_error_px = 0;
  int num_observations = 0;  // corners of the images that were used
  int num_not_visible = 0;
  // Per image index, as rms_error_px (0 for an image without corners).
  std::vector<double> image_rms_error_px;
  // Per observation (the input's order): the reprojection error in pixels,
  // or -1 where the model does not see the corner or its image was skipped.
  std::vector<double> observation_errors_px;
  // The start that won: its focal length and whether it was the equidistant
  // fit (true) or the model's InitialParams (false).
  double initial_focal_length = 0;
  bool initial_from_equidistant = false;
};

// Fits the model with the given id (camera_models/registry.h) to the
// observations of an image of width x height pixels. Throws
// std::invalid_argument for an unknown model id, bad options, an image size
// that is not positive, or a board point off the plane z = 0.
LensFitResult FitLens(int model_id, int width, int height,
                      const std::vector<BoardObservation>& observations,
                      const LensFitOptions& options = LensFitOptions());

// The pose of a planar board (points with z = 0) from unit rays towards its
// points: the homography of rays, its sign chosen so that the points lie in
// front along their rays, and the nearest rotation. False when fewer than 4
// points or the points are degenerate (collinear).
bool BoardPoseFromRays(const std::vector<Eigen::Vector3d>& points_in_board,
                       const std::vector<Eigen::Vector3d>& rays_in_cam,
                       Eigen::Quaterniond* cam_from_board_rotation,
                       Eigen::Vector3d* cam_from_board_translation);

}  // namespace sphera
