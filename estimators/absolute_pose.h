// SPHERA estimators: absolute pose of a central spherical camera from
// ray <-> world-point correspondences.
//
// Mathematics
// -----------
// cam_from_world = [R | t], x_cam = R x_world + t.  Observation i is a unit
// ray u_i in the camera and a world point X_i; the angular error is
//   theta_i = angle(u_i, R X_i + t) = atan2(|u_i x v_i|, u_i . v_i),
//   v_i = R X_i + t,
// in [0, pi]; a point behind the ray (u_i . v_i < 0) has theta_i > 90 deg and
// is therefore naturally an outlier.  No image plane is involved, so rays may
// point anywhere on S^2 (360-degree cameras).
//
// Minimal solver: OpenGV p3p_kneip (Kneip et al. CVPR 2011), which works on
// bearing vectors and returns up to 4 poses as [R_wc | c] (camera-to-world
// rotation, centre in world); converted by R = R_wc^T, t = -R_wc^T c.
// Non-minimal solver: OpenGV UPnP (Kneip et al. ECCV 2014, bearing-based),
// best solution by angular error, then Ceres refinement of sum theta_i^2.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "estimators/eigen_types.h"

namespace sphera {

// Squared angular error theta^2 [rad^2] of a ray / world point under
// cam_from_world.
double SquaredRayPointAngle(const Eigen::Vector3d& ray,
                            const Eigen::Vector3d& point3D,
                            const Eigen::Matrix3x4d& cam_from_world);

// RANSAC estimator (COLMAP concept).
//   X_t: unit ray in the camera; Y_t: world point; M_t: cam_from_world.
//   kMinNumSamples = 3 (P3P, up to 4 models, only poses with all 3 sample
//   points in front of their rays are returned); more samples: UPnP + Ceres
//   refinement (for LO-RANSAC).
//   Residual: SquaredRayPointAngle [rad^2].
class P3PRayEstimator {
 public:
  typedef Eigen::Vector3d X_t;
  typedef Eigen::Vector3d Y_t;
  typedef Eigen::Matrix3x4d M_t;
  static constexpr int kMinNumSamples = 3;

  static void Estimate(const std::vector<X_t>& rays,
                       const std::vector<Y_t>& points3D,
                       std::vector<M_t>* models);
  static void Residuals(const std::vector<X_t>& rays,
                        const std::vector<Y_t>& points3D,
                        const M_t& cam_from_world,
                        std::vector<double>* residuals);
};

struct AbsolutePoseRefineOptions {
  // Cauchy loss scale [rad]; <= 0: plain least squares.
  double loss_scale_rad = 0;
  int max_num_iterations = 100;
};

// Ceres refinement of cam_from_world minimising sum_i theta_i^2 with the
// log-map angular residual (AngularReprojectionCost, points held constant;
// rotation as quaternion on ceres::QuaternionManifold).
//   inlier_mask: empty = all; otherwise size N, nonzero = use.
bool RefineAbsolutePose(const std::vector<Eigen::Vector3d>& rays,
                        const std::vector<Eigen::Vector3d>& points3D,
                        const std::vector<char>& inlier_mask,
                        Eigen::Matrix3x4d* cam_from_world,
                        const AbsolutePoseRefineOptions& options =
                            AbsolutePoseRefineOptions());

}  // namespace sphera
