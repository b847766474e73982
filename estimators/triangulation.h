// SPHERA estimators: triangulation of a 3D point from unit bearing rays.
//
// Mathematics
// -----------
// View i has pose cam_from_world_i = [R_i | t_i] (x_cam = R_i x_world + t_i)
// and observes the point X along the unit ray u_i.  The ray constraint
// "R_i X + t_i is parallel to u_i" is equivalent to the two linear equations
//   e1_i . (R_i X + t_i) = 0,   e2_i . (R_i X + t_i) = 0,
// where (e1_i, e2_i) is the tangent basis of u_i (angular_residual.h).  For
// the homogeneous point X_h = (X, 1) this is A X_h = 0 with rows
// e_k^T [R_i | t_i]; the DLT solution is the right singular vector of the
// smallest singular value of A (2N x 4).  These constraints do not see the
// sign of the ray (they also accept -u_i); cheirality u_i . (R_i X + t_i) > 0
// is checked separately.  Works for rays anywhere on the sphere (no z > 0
// assumption).
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "estimators/eigen_types.h"

namespace sphera {

// Linear (DLT) triangulation from N >= 2 rays.  Returns std::nullopt if there
// are fewer than 2 observations, or the solution is at infinity / degenerate.
// Does NOT check cheirality (use CheckRayCheirality).
std::optional<Eigen::Vector3d> TriangulateRays(
    const std::vector<Eigen::Matrix3x4d>& cams_from_world,
    const std::vector<Eigen::Vector3d>& rays);

// Camera centre of cam_from_world = [R | t]:  C = -R^T t.
Eigen::Vector3d ProjectionCenter(const Eigen::Matrix3x4d& cam_from_world);

// Geodesic angle [rad, in [0, pi]] between the observed ray and the direction
// of the point in the camera, R X + t.
double RayAngularError(const Eigen::Vector3d& ray,
                       const Eigen::Matrix3x4d& cam_from_world,
                       const Eigen::Vector3d& point3D);

// Cheirality on the sphere: the point lies in the open half-space in front of
// the ray, ray . (R X + t) > 0, i.e. angular error < 90 deg.
bool HasPositiveRayDepth(const Eigen::Vector3d& ray,
                         const Eigen::Matrix3x4d& cam_from_world,
                         const Eigen::Vector3d& point3D);

// True iff HasPositiveRayDepth for every observation.
bool CheckRayCheirality(const std::vector<Eigen::Matrix3x4d>& cams_from_world,
                        const std::vector<Eigen::Vector3d>& rays,
                        const Eigen::Vector3d& point3D);

// Non-linear refinement of the point minimising sum_i theta_i^2 (log-map
// angular residual, fixed cameras).  Returns false if Ceres fails.
bool RefineTriangulatedPoint(
    const std::vector<Eigen::Matrix3x4d>& cams_from_world,
    const std::vector<Eigen::Vector3d>& rays, Eigen::Vector3d* point3D,
    int max_num_iterations = 50);

}  // namespace sphera
