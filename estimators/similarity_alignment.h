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

}  // namespace sphera
