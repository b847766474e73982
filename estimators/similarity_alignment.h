// Alignment of a reconstruction to ground truth without reprojection: the
// rotation of the similarity from the camera orientations (robustly), its
// scale and translation from the camera centres.
//
// Why not a similarity on centres alone: with centre errors e over baselines
// b, the rotation of a centre-only fit is uncertain by about e / b, which for
// sub-millimetre reconstructions is as large as the orientation errors being
// measured. Each camera i gives an exact estimate of the world rotation,
// R_gt_i^T R_est_i; their geodesic median ignores a minority of wrong
// cameras.
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

namespace sphera {

// Geodesic L1 median on SO(3): argmin_R sum_i ||log(R^T R_i)|| (Weiszfeld
// iterations in the tangent space, with the optimality test at a data point
// so that a majority of identical rotations is returned exactly).
Eigen::Matrix3d GeodesicMedianRotation(
    const std::vector<Eigen::Matrix3d>& rotations);

// Least-squares scale s and translation t of tgt_i ≈ s R src_i + t for a
// given rotation R. False with fewer than 2 points or coincident sources.
bool AlignCentersWithRotation(const std::vector<Eigen::Vector3d>& src_centers,
                              const std::vector<Eigen::Vector3d>& tgt_centers,
                              const Eigen::Matrix3d& tgt_from_src_rotation,
                              double* tgt_from_src_scale,
                              Eigen::Vector3d* tgt_from_src_translation);

// One rig frame registered in two models of one run: its rig_from_world
// pose in each (x_rig = R x_world + t), and the positions in each model of
// the 3D points that both models triangulated from the same keypoints of the
// frame's images.
struct SharedRigFrame {
  Eigen::Matrix3d src_rotation;
  Eigen::Vector3d src_translation;
  Eigen::Matrix3d tgt_rotation;
  Eigen::Vector3d tgt_translation;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> src_tgt_points;
};

// The similarity tgt ≈ s R src + t that puts a shared frame where both models
// have it. Rotation and centre come from the frames (the geodesic median of
// R_tgt^T R_src; the mean of c_tgt - s R c_src), which each model determines
// from all of the frame's observations; the scale, which a frame alone does
// not give, is the median over the common points of the ratio of their
// distances from the frame's origin (tgt / src), robust to the poorly
// triangulated points of a capture that mostly rotates.
struct SharedFrameAlignment {
  double scale = 1;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  // Points the scale was taken from (0: `fallback_scale`), and the median
  // absolute deviation of their log ratios (0.1: the ratios spread by about
  // 10%).
  int num_points = 0;
  double log_scale_spread = 0;
};

// With fewer than `min_points` common points (both distances positive) the
// scale is `fallback_scale` if positive (e.g. the ratio of the rig's lens
// offsets in the two models), else the alignment fails. False also without
// frames.
bool AlignViaSharedRigFrames(const std::vector<SharedRigFrame>& frames,
                             int min_points,
                             double fallback_scale,
                             SharedFrameAlignment* alignment);

}  // namespace sphera
