// Two-view geometry on bearing rays, for pairs that involve a sphere camera
// (colmap_ext/sensor/sphere_models.h): the essential matrix from rays with
// OpenGV's five-point solver inside COLMAP's LO-RANSAC, inliers by angular
// epipolar error (the pixel threshold converted per camera), pure-rotation
// ("panoramic") pairs detected with a rotation-only model, and the relative
// pose chosen by ray cheirality (ray . X > 0), so rays behind the image plane
// take part like any other.
#pragma once

#include "colmap/estimators/two_view_geometry.h"
#include "colmap/scene/camera.h"

#include <vector>

#include <Eigen/Core>

namespace colmap {

// True when the pair needs the ray-based estimators: either camera is a
// sphere camera. Perspective-only pairs keep COLMAP's estimators.
bool UseRayTwoViewGeometry(const Camera& camera1, const Camera& camera2);

TwoViewGeometry EstimateRayTwoViewGeometry(
    const Camera& camera1,
    const std::vector<Eigen::Vector2d>& points1,
    const Camera& camera2,
    const std::vector<Eigen::Vector2d>& points2,
    const FeatureMatches& matches,
    const TwoViewGeometryOptions& options);

// Relative pose, triangulation angle and configuration refinement of a
// CALIBRATED or PANORAMIC ray geometry, as EstimateTwoViewGeometryPose.
bool EstimateRayTwoViewGeometryPose(const Camera& camera1,
                                    const std::vector<Eigen::Vector2d>& points1,
                                    const Camera& camera2,
                                    const std::vector<Eigen::Vector2d>& points2,
                                    TwoViewGeometry* geometry);

}  // namespace colmap
