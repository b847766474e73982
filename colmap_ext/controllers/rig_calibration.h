// The calibration a reconstruction recovered for its rigs of lenses
// (`colmap rig_calibration`), readable and reusable.
//
// For every rig of the model with more than one sensor, per lens (camera;
// named by the folder of its images, e.g. "lens0"): model and parameters,
// focal lengths and their ratio, the focal length on the optical axis, and
// the field of view (twice the largest angle from the optical axis of the
// rays of the pixels inside the disc of radius_fraction x min(width,
// height) around the principal point); per sensor: its pose relative to the
// reference lens (rotation angle, the azimuth and elevation of its optical
// axis, and the lens centre in the rig). With a
// ground truth (a model of the same images, e.g. the renderer's sparse_gt
// with rigs.txt): per lens the difference of the projections over that disc
// (ground-truth pixel -> ray -> estimated pixel; median and max in pixels)
// and the focal ratios, per sensor the rotation error and the centre error,
// scaled to the ground truth by EvaluateModel's alignment of the camera
// centres (model_evaluation.h).
#pragma once

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/reconstruction.h"

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace colmap {

struct RigCalibrationOptions {
  // In (0, 1]: the disc of the field of view and projection differences.
  double radius_fraction = 0.5;

  // Empty, or why an option is out of its range (naming the option).
  std::string Check() const;
};

struct LensCalibration {
  camera_t camera_id = kInvalidCameraId;
  std::string name;
  bool reference = false;
  Camera camera;
  double fov_deg = 0;
  // Pixels per radian along x and y at the optical axis (NaN if the model
  // does not project the axis' neighbourhood).
  Eigen::Vector2d axis_focal = Eigen::Vector2d::Zero();
  std::optional<Rigid3d> sensor_from_rig;
  // Rotation from the reference lens and the lens centre in the rig (in
  // the ground truth's units when there is one).
  double rotation_from_reference_deg = 0;
  // The lens's optical axis in the reference lens's frame: its azimuth
  // about the reference's vertical (image y) axis, from the reference's
  // axis (0) towards its image x (90; +-180: facing the other way), and its
  // elevation towards the reference's image up (-y). A back lens turned
  // 180 deg about the vertical and tilted has a rotation angle near 180
  // whatever its tilt; these two show the tilt.
  double axis_azimuth_deg = 0;
  double axis_elevation_deg = 0;
  Eigen::Vector3d centre_in_rig = Eigen::Vector3d::Zero();
  // With ground truth.
  std::optional<double> projection_median_px, projection_max_px, focal_ratio,
      axis_focal_ratio;
  std::optional<double> rotation_error_deg, centre_error;
};

struct RigCalibration {
  rig_t rig_id = kInvalidRigId;
  std::vector<LensCalibration> lenses;  // the reference lens first
};

struct RigCalibrationReport {
  bool with_ground_truth = false;
  // Ground truth's units per model unit (1 without ground truth).
  double scale = 1;
  std::vector<RigCalibration> rigs;
};

// The calibration of every rig of `model` with more than one sensor,
// compared with `ground_truth` when it is not null. Throws
// std::invalid_argument with a message for bad options, a model without
// such a rig, or a ground truth that cannot be aligned.
RigCalibrationReport CalibrateRigs(const Reconstruction& model,
                                   const Reconstruction* ground_truth,
                                   const RigCalibrationOptions& options);

// The report as the command prints it.
std::string RigCalibrationText(const RigCalibrationReport& report);
// Every figure of the report (rig_calibration.json).
std::string RigCalibrationJson(const RigCalibrationReport& report);
// The calibration in rig_configurator's format (rig_config.json): lens
// offsets in the model's units, or the ground truth's with one.
std::string RigConfigJson(const RigCalibrationReport& report);

}  // namespace colmap
