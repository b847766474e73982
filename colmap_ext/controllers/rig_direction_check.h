// Does a database's rig config agree with its images? (`colmap rig_check`)
//
// For every verified image pair inside one frame of a rig (two lenses of
// one capture), the inlier matches are lifted to unit rays in each lens and
// the rotation between the lenses is fitted (estimators/
// rotation_from_rays.h); estimators/rig_direction_check.h then names the
// lenses whose configured direction (the database's sensor_from_rig, as
// rig_configurator wrote it) these rotations contradict, and by how much.
// Run after matching, before mapping: a wrong lens direction otherwise
// sends the rig mapper into a long fruitless search.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "colmap/scene/database.h"
#include "estimators/rig_direction_check.h"

namespace colmap {

struct RigCheckOptions {
  // A lens whose configured direction is off by more than this (its pairs
  // disagree by more) is named. In (0, 180].
  double max_angle_deg = 10;
  // A matched ray pair fits the rotation within this angle; room for the
  // parallax of the lenses' baseline. In (0, 90).
  double max_ray_error_deg = 4;
  // A lens pair in a frame with fewer inlier rays is not measured.
  int min_num_inliers = 15;

  // Empty, or why an option is out of its range (naming the option).
  std::string Check() const;
};

struct LensCheck {
  rig_t rig_id = kInvalidRigId;
  camera_t camera_id = kInvalidCameraId;
  bool reference = false;
  // What the names of the lens's images share: their folder "lens2/", or
  // "*_3.JPG".
  std::string image_pattern;
  // Frames in which the lens has a measured pair.
  int num_frames = 0;
  // False when the database has no sensor_from_rig for the lens.
  bool configured = false;
  Eigen::Matrix3d config_cam_from_rig = Eigen::Matrix3d::Identity();
  sphera::LensDirection direction;
};

struct RigCheckReport {
  int num_rigs = 0;        // rigs of more than one camera
  int num_frames = 0;      // frames of those rigs
  int num_frame_pairs = 0;  // verified image pairs inside one frame
  int num_measured_pairs = 0;  // of those, with a fitted rotation
  std::vector<LensCheck> lenses;  // per rig, the reference lens first
};

// Reads the database (never writes). Throws std::invalid_argument with a
// message naming what is missing when it has no rig of more than one
// camera or no frame of one; a database without verified pairs inside
// frames gives a report whose lenses are all unchecked.
RigCheckReport CheckRigDirectionsInDatabase(const Database& database,
                                            const RigCheckOptions& options);

// The same for the database file at `path`, which is left byte for byte
// as it was: COLMAP's database opens for writing (it creates missing tables
// and sets the schema version), so a temporary copy is read. A path that is
// no database file throws std::invalid_argument naming it.
RigCheckReport CheckRigDirectionsInDatabaseFile(
    const std::filesystem::path& path, const RigCheckOptions& options);

// "rig R camera C (PATTERN)".
std::string LensCheckName(const LensCheck& lens);

// The report, one line per lens: degrees off (or why unchecked), lens
// pairs, frames, inlier rays; "CONTRADICTED" for a named lens.
std::string RigCheckText(const RigCheckReport& report);

// Why a contradicted lens is named: how far its configured direction is
// from what its images say, both directions (optical axis in the rig and
// cam_from_rig_rotation [w, x, y, z] as rig_config.json writes it).
std::string LensContradictionText(const LensCheck& lens,
                                  const RigCheckOptions& options);

}  // namespace colmap
