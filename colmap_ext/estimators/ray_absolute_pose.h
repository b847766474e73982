// Absolute pose of a sphere camera from 2D-3D correspondences on rays: P3P on
// bearing rays (OpenGV, Kneip) inside COLMAP's LO-RANSAC with the inlier test
// on the angle between the observed ray and the point, so points behind the
// image plane register like any other and no image seam can split an inlier.
// Pose refinement then uses the angular residual of
// colmap_ext/estimators/sphere_cost_functions.h through RefineAbsolutePose.
#pragma once

#include "colmap/estimators/pose.h"

namespace colmap {

// As EstimateAbsolutePose, for cameras with CameraModelIsSphere (the focal
// length is not estimated).
bool EstimateRayAbsolutePose(const AbsolutePoseEstimationOptions& options,
                             const std::vector<Eigen::Vector2d>& points2D,
                             const std::vector<Eigen::Vector3d>& points3D,
                             Rigid3d* cam_from_world,
                             const Camera& camera,
                             size_t* num_inliers,
                             std::vector<char>* inlier_mask);

}  // namespace colmap
