// The rotation between two cameras with (nearly) the same centre from
// corresponding unit rays: cam2_from_cam1 with ray_in_cam2 ≈ R ray_in_cam1.
//
// Why a pure rotation fits two lenses of one rig frame: the lenses are a few
// centimetres apart and the scene metres away, so the parallax between
// their rays is at most baseline / depth (6 cm at 2 m: 1.7°), below the
// inlier threshold. RANSAC over minimal samples of 2 rays (the rotation that
// maps one orthonormal triad onto the other), then a least-squares refit on
// the inliers (Kabsch without translation and scale: R = U diag(1, 1, det)
// V^T from the SVD of sum ray_in_cam2 ray_in_cam1^T).
#pragma once

#include <stdexcept>
#include <vector>

#include <Eigen/Core>

namespace sphera {

struct RotationFromRaysOptions {
  // A correspondence is an inlier when the angle between ray_in_cam2 and
  // R ray_in_cam1 is below this. The default leaves room for the parallax
  // of a 6 cm baseline at 1 m (3.4°).
  double max_error_rad = 4.0 * 3.14159265358979323846 / 180;
  // RANSAC stops after this many samples, or earlier when the probability
  // of having missed the best model is below 1 - confidence.
  int max_num_trials = 2000;
  double confidence = 0.9999;
  // Fewer inliers than this is no estimate.
  int min_num_inliers = 8;
  unsigned int random_seed = 0;

  // Throws std::invalid_argument naming the option that is out of range.
  void Check() const;
};

struct RotationFromRays {
  bool success = false;
  Eigen::Matrix3d cam2_from_cam1 = Eigen::Matrix3d::Identity();
  std::vector<char> inlier_mask;
  int num_inliers = 0;
};

// The least-squares rotation R minimising sum |ray_in_cam2_i - R
// ray_in_cam1_i|^2 (Kabsch). Identity for fewer than 2 rays.
Eigen::Matrix3d FitRotationToRays(
    const std::vector<Eigen::Vector3d>& rays_in_cam1,
    const std::vector<Eigen::Vector3d>& rays_in_cam2);

// Robust cam2_from_cam1 from corresponding unit rays (same length; throws
// std::invalid_argument otherwise).
RotationFromRays EstimateRotationFromRays(
    const std::vector<Eigen::Vector3d>& rays_in_cam1,
    const std::vector<Eigen::Vector3d>& rays_in_cam2,
    const RotationFromRaysOptions& options);

}  // namespace sphera
