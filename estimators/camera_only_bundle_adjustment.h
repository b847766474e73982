// SPHERA estimators: camera-only bundle adjustment over re-triangulated
// reliable points (Gava & Stricker, VISAPP 2015, Eqs. 4, 6, 7).
//
// Method
// ------
// The unknowns are the camera poses cam_from_world = (R_i, t_i) only; the 3D
// points are NOT parameters. Each outer iteration k does:
//
//   1. re-triangulate every track from the current poses: linear triangulation
//      on the rays (TriangulateRays) followed by the angular refinement
//      (RefineTriangulatedPoint, min sum theta^2);
//   2. select the reliable points (Eq. 7): a track is reliable iff it was
//      triangulated, every observation is in front of its ray (cheirality)
//      and every observation's angular error theta_ij = angle(u_ij, R_i X_j +
//      t_i) (Eq. 4) is <= tau_i, the threshold of its image in radians
//      (tau in pixels times the camera's radians per pixel);
//   3. optimise the poses over the reliable points (Eq. 6):
//        min_P sum_{j reliable} sum_{i in track j}
//              rho(|Log_u_ij(R_i X_j(P) + t_i)|^2)
//      with the exact log-map angular residual of angular_residual.h and
//      rho = identity or Cauchy (scale in radians). The points are never
//      parameters of the result: X_j(P) is the triangulation from the poses.
//      X_j(P) is a function of the poses inside the step: every
//      Gauss-Newton step eliminates the points by the Schur complement
//      (variable projection: the reduced camera system of the objective in
//      the poses only) and the optimised point values are discarded
//      afterwards. Holding the points constant instead (the textbook
//      resection-intersection alternation) converges only linearly, about
//      2% error reduction per iteration on the 9-camera room;
//   4. optionally let a caller-supplied step refine intrinsics and re-lift the
//      rays (this header knows only rays, not pixels);
//   5. stop when the relative change of the cost is <= function_tolerance,
//      when no pose moved by more than parameter_tolerance, or after
//      max_iterations. A final re-triangulation + selection from the refined
//      poses gives the returned reliable points.
//
// Gauge
// -----
// The objective is invariant under a similarity of all poses (the points
// follow the poses), so the gauge is fixed: the pose of camera gauge_image0
// (default 0) is held constant and the centre of camera gauge_image1
// (default 1) is constrained to the sphere of radius d = |C1 - C0| around C0
// (C1 = C0 + d n, n on ceres::SphereManifold<3>), so rotation, translation and
// scale of the input are kept: the result lives in the input's frame. In the
// pose step every camera is parametrised by (q, C) with v = R (X - C);
// t = -R C is written back.
//
// Failure statuses: kInvalidInput (inconsistent sizes, bad rays, bad
// options), kTooFewObservations (an image observes fewer than
// min_observations_per_image track points, or keeps fewer reliable ones),
// kNoReliablePoints (tau is below the noise floor: no track has every
// observation within tau), kDegenerateGeometry (the two gauge cameras share
// their centre, or a camera's pose is not determined by its reliable points,
// e.g. all points on one line through the centre), kSolverFailure (Ceres or
// the intrinsics step failed). The message names the parameter or image.
//
// No COLMAP headers: Eigen and Ceres only.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimators/eigen_types.h"

namespace sphera {

// x_cam = rotation * x_world + translation.
struct CameraPose {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Matrix3x4d Matrix() const;
  Eigen::Vector3d Center() const { return -(rotation.conjugate() * translation); }
};

// One observation of a track: the image index (into the pose vector) and the
// unit bearing ray in that camera's frame.
struct RayObservation {
  int image_idx = -1;
  Eigen::Vector3d ray = Eigen::Vector3d::UnitZ();
};
using RayTrack = std::vector<RayObservation>;

struct CameraOnlyBAProblem {
  std::vector<CameraPose> poses;  // initial cam_from_world per image
  std::vector<RayTrack> tracks;   // observations per track
};

// A reliable point: the track it comes from, its re-triangulated position and
// the angular errors of its observations (same order as the track).
struct ReliablePoint {
  int track_idx = -1;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::vector<double> errors_rad;
};

enum class CameraOnlyBAStatus {
  kSuccess = 0,
  kInvalidInput,
  kTooFewObservations,
  kNoReliablePoints,
  kDegenerateGeometry,
  kSolverFailure,
};
const char* CameraOnlyBAStatusName(CameraOnlyBAStatus status);

enum class CameraOnlyBALoss { kNone, kCauchy };

struct CameraOnlyBAOptions {
  // Reliability threshold tau per image [rad]: tau_rad_fn (if set) takes
  // precedence and is re-evaluated every iteration (intrinsics may change the
  // radians per pixel); else tau_rad with one entry for every image or a
  // single entry for all. Every value must be > 0.
  std::function<double(int image_idx)> tau_rad_fn;
  std::vector<double> tau_rad;

  int max_iterations = 20;          // outer iterations (>= 1)
  double function_tolerance = 1e-6; // stop: |cost_k - cost_{k-1}| <= tol cost_{k-1}
  double parameter_tolerance = 1e-12;  // stop: max pose change [rad or m rel.]
  CameraOnlyBALoss loss = CameraOnlyBALoss::kNone;
  double loss_scale_rad = 1e-3;     // Cauchy scale [rad]

  // Gauge: pose of gauge_image0 fixed, |C(gauge_image1) - C0| fixed.
  int gauge_image0 = 0;
  int gauge_image1 = 1;

  // Every image must observe at least this many points of tracks with >= 2
  // observations, and keep at least this many reliable observations.
  int min_observations_per_image = 6;
  // A pose whose normal matrix (scale-normalised) has an eigenvalue ratio
  // below this is "not determined by its points" -> kDegenerateGeometry.
  double min_pose_conditioning = 1e-10;

  int max_num_pose_iterations = 100;   // Ceres iterations per pose step
  int max_num_point_iterations = 20;   // Ceres iterations per point refinement
  bool refine_points = true;           // angular refinement after linear
  int num_threads = 1;

  // Optional intrinsics step, called after every pose step with the current
  // poses and reliable points (held fixed). It may refine intrinsics (and,
  // because focal length and pose are coupled, the poses of the cameras it
  // calibrates, except the gauge images) and must then re-lift the rays in
  // *tracks (same layout, only the rays change). Returning false aborts with
  // kSolverFailure.
  std::function<bool(std::vector<CameraPose>* poses,
                     const std::vector<ReliablePoint>& points,
                     std::vector<RayTrack>* tracks)>
      intrinsics_step;

  bool verbose = false;  // one line per iteration on stderr
};

struct CameraOnlyBAIterationStats {
  int iteration = 0;
  int num_reliable_points = 0;
  int num_reliable_observations = 0;
  double mean_error_before_rad = 0;  // reliable obs., before the pose step
  double mean_error_after_rad = 0;   // same obs./points, after the pose step
  double cost_before = 0;            // 0.5 sum rho(theta^2)
  double cost_after = 0;
  double max_pose_change = 0;        // max rotation [rad] / centre change rel.
};

struct CameraOnlyBAResult {
  CameraOnlyBAStatus status = CameraOnlyBAStatus::kInvalidInput;
  std::string message;
  // The image (index into the problem's poses) that a failure concerns, or
  // -1; the message does not repeat it, so the caller can name the image.
  int image_idx = -1;
  std::vector<CameraPose> poses;          // refined (input poses on failure)
  std::vector<ReliablePoint> points;      // reliable points at the final poses
  std::vector<CameraOnlyBAIterationStats> iterations;
  // Mean angular error over the reliable observations before the first pose
  // step and after the final re-triangulation.
  double initial_mean_error_rad = 0;
  double final_mean_error_rad = 0;
  int num_triangulated_tracks = 0;  // at the final poses
  double elapsed_seconds = 0;

  bool Success() const { return status == CameraOnlyBAStatus::kSuccess; }
};

// Re-triangulate every track from the poses and select the reliable ones.
// Tracks with < 2 observations, failed triangulation or failed cheirality are
// never reliable. tau_rad[i] is the threshold of image i. Returns the number
// of triangulated tracks through num_triangulated (may be null).
std::vector<ReliablePoint> TriangulateReliablePoints(
    const std::vector<CameraPose>& poses, const std::vector<RayTrack>& tracks,
    const std::vector<double>& tau_rad, bool refine_points,
    int max_num_point_iterations, int* num_triangulated = nullptr);

CameraOnlyBAResult CameraOnlyBundleAdjustment(
    const CameraOnlyBAProblem& problem, const CameraOnlyBAOptions& options);

}  // namespace sphera
