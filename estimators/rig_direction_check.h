// Which lens directions of a rig config the images contradict.
//
// Input: the config's rotation cam_from_rig of every lens, and rotations
// cam2_from_cam1 measured between two lenses of one frame (from their
// matched rays, rotation_from_rays.h). Per lens pair the measurements of
// all frames combine by their geodesic median (a few frames with a wrong
// rotation do not move it); the config predicts cam2_from_rig
// cam1_from_rig^T for the pair, and the pair disagrees when the two differ
// by more than max_disagreement_rad.
//
// Which lens of a disagreeing pair is wrong: greedily the lens with the
// largest share of disagreeing pairs among the lenses not yet named (ties:
// the larger sum of disagreement, then the later lens, since the first lens
// is usually the rig's reference), until no pair among the remaining lenses
// disagrees. Every lens's direction is then measured from its pairs with
// the remaining (consistent) lenses: cam_from_rig ≈ cam_from_other
// other_from_rig per pair, combined by their geodesic median; its angle
// from the config's is how far the config is off. A lens with no measured
// pair is unchecked.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace sphera {

// One rotation measured between lenses `lens1` and `lens2` (indices into
// the config's lenses) in one frame.
struct LensPairRotation {
  int lens1 = -1;
  int lens2 = -1;
  Eigen::Matrix3d cam2_from_cam1 = Eigen::Matrix3d::Identity();
  int num_inliers = 0;
};

struct RigDirectionCheckOptions {
  // A lens pair disagrees with the config beyond this angle.
  double max_disagreement_rad = 10.0 * 3.14159265358979323846 / 180;

  // Throws std::invalid_argument naming the option that is out of range.
  void Check() const;
};

enum class LensDirectionStatus {
  kUnchecked,     // no measured pair with another lens
  kConsistent,    // every pair with a consistent lens agrees with the config
  kContradicted,  // named: its pairs disagree with the config
};

struct LensDirection {
  LensDirectionStatus status = LensDirectionStatus::kUnchecked;
  // Whether measured_cam_from_rig and angle_off_rad are set: the lens has a
  // measured pair with a consistent lens.
  bool measured = false;
  Eigen::Matrix3d measured_cam_from_rig = Eigen::Matrix3d::Identity();
  // Angle between the measured and the config's cam_from_rig.
  double angle_off_rad = 0;
  // Lens pairs measured (with any lens), their measurements (one per pair
  // and frame) and the inlier rays of those.
  int num_pairs = 0;
  int num_measurements = 0;
  int num_inliers = 0;
  // The largest disagreement of its pairs with the config.
  double max_pair_disagreement_rad = 0;
};

// One entry per lens of config_cam_from_rig. Throws std::invalid_argument
// for a measurement of a lens index out of range or of a lens with itself.
std::vector<LensDirection> CheckRigDirections(
    const std::vector<Eigen::Matrix3d>& config_cam_from_rig,
    const std::vector<LensPairRotation>& measurements,
    const RigDirectionCheckOptions& options);

// The optical axis (z) of a lens turned CAM_FROM_REF from a reference lens,
// in the reference lens's frame: x its azimuth about the reference's
// vertical (image y) axis, from the reference's axis (0) towards its image
// x (90; +-180 facing the other way); y its elevation towards the
// reference's image up (-y). Degrees. A back lens turned 180 deg about a
// slightly tilted axis is still turned 180 deg; its axis shows the tilt.
Eigen::Vector2d LensAxisAzimuthElevationDeg(
    const Eigen::Matrix3d& cam_from_ref);

}  // namespace sphera
