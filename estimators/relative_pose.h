// SPHERA estimators: relative pose of two central spherical cameras.
//
// Mathematics
// -----------
// Convention: cam2_from_cam1 = (R, t), x2 = R x1 + t.  A point seen along unit
// rays r1 (camera 1) and r2 (camera 2) satisfies d2 r2 = R (d1 r1) + t, so r2,
// R r1 and t are coplanar:
//   r2 . (t x R r1) = r2^T E r1 = 0,   E = [t]_x R      (essential matrix).
// The constraint is homogeneous in each ray, hence it holds for rays anywhere
// on S^2 (including behind z = 0) and is blind to the ray sign; the sign is
// used later, in the cheirality test.
//
// Angular epipolar error.  n2 = E r1 is the normal of the epipolar plane of r1
// in camera 2 and n1 = E^T r2 the normal of the epipolar plane of r2 in
// camera 1.  The angle between a unit ray r and the plane with normal n is
//   theta = asin(|n . r| / |n|) = atan2(|n . r|, |n x r|)
// (the atan2 form is used: accurate everywhere, smooth, no asin).  Note
// n1 . r1 = n2 . r2 = r2^T E r1.  The symmetric squared error used as RANSAC
// residual is  (theta1^2 + theta2^2) / 2  [rad^2].
//
// OpenGV convention: its E_gv = [t_gv]_x R_gv with f1^T E_gv f2 = 0, where
// R_gv = R^T (camera 2 to camera 1) and t_gv = -R^T t (centre of camera 2 in
// camera 1).  Ours is E = E_gv^T.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "estimators/eigen_types.h"

namespace sphera {

// Essential matrix E = [t]_x R of cam2_from_cam1 = (R, t).
Eigen::Matrix3d EssentialMatrixFromPose(const Eigen::Matrix3d& cam2_from_cam1_R,
                                        const Eigen::Vector3d& cam2_from_cam1_t);

// Symmetric squared angular epipolar error (theta1^2 + theta2^2) / 2 [rad^2]
// of the ray pair under E (ray2^T E ray1 = 0).  Rays need not be unit.
double SquaredAngularEpipolarError(const Eigen::Matrix3d& E,
                                   const Eigen::Vector3d& ray1,
                                   const Eigen::Vector3d& ray2);

// RANSAC estimator (COLMAP concept) for the essential matrix from rays.
//   X_t = Y_t = unit rays in camera 1 / camera 2; M_t = E, ray2^T E ray1 = 0.
//   Minimal (5 rays): OpenGV Stewenius 5-point (real roots, up to 10 models).
//   Non-minimal (6-7): 5-point on the least-squares null space;
//   (>= 8): OpenGV 8-point, projected onto the essential manifold
//   (singular values (1, 1, 0)).
//   Residual: SquaredAngularEpipolarError [rad^2].
class EssentialMatrixRayEstimator {
 public:
  typedef Eigen::Vector3d X_t;
  typedef Eigen::Vector3d Y_t;
  typedef Eigen::Matrix3d M_t;
  static constexpr int kMinNumSamples = 5;

  static void Estimate(const std::vector<X_t>& rays1,
                       const std::vector<Y_t>& rays2,
                       std::vector<M_t>* models);
  static void Residuals(const std::vector<X_t>& rays1,
                        const std::vector<Y_t>& rays2, const M_t& E,
                        std::vector<double>* residuals);
};

// The four (R, t) with [t]_x R ~ E, |t| = 1:  E = U diag(1,1,0) V^T
// (det U, det V > 0),  R in {U W V^T, U W^T V^T},  t = +/- U e3.
void DecomposeEssentialMatrix(const Eigen::Matrix3d& E, Eigen::Matrix3d* R1,
                              Eigen::Matrix3d* R2, Eigen::Vector3d* t);

// Recover cam2_from_cam1 (R, t; |t| = 1) from E.  Each of the 4
// decompositions triangulates all (masked) correspondences; a point X (camera-1
// frame) passes cheirality iff ray1 . X > 0 and ray2 . (R X + t) > 0 and its
// depth is below 1000 |t| (COLMAP's bound against points at infinity).  The
// decomposition with most passing points wins.
//   inlier_mask: empty = use all; otherwise size N, nonzero = use.
//   points3D (optional): the passing points (camera-1 frame), COLMAP semantics.
//   point_mask (optional): size N, 1 where the correspondence produced a
//   point in points3D.
// Returns the number of passing points (0 if E is unusable).
size_t RelativePoseFromEssential(const Eigen::Matrix3d& E,
                                 const std::vector<Eigen::Vector3d>& rays1,
                                 const std::vector<Eigen::Vector3d>& rays2,
                                 const std::vector<char>& inlier_mask,
                                 Eigen::Matrix3d* cam2_from_cam1_R,
                                 Eigen::Vector3d* cam2_from_cam1_t,
                                 std::vector<Eigen::Vector3d>* points3D = nullptr,
                                 std::vector<char>* point_mask = nullptr);

// RANSAC estimator (COLMAP concept) for a pure rotation (panoramic pair,
// zero baseline): ray2 ~ R ray1.
//   X_t = Y_t = unit rays; M_t = R = cam2_from_cam1 rotation.
//   Estimate: uncentred Kabsch (Wahba) on the rays, least squares for N >= 2.
//   Residual: squared angle between ray2 and R ray1 [rad^2].
class RotationOnlyEstimator {
 public:
  typedef Eigen::Vector3d X_t;
  typedef Eigen::Vector3d Y_t;
  typedef Eigen::Matrix3d M_t;
  static constexpr int kMinNumSamples = 2;

  static void Estimate(const std::vector<X_t>& rays1,
                       const std::vector<Y_t>& rays2,
                       std::vector<M_t>* models);
  static void Residuals(const std::vector<X_t>& rays1,
                        const std::vector<Y_t>& rays2, const M_t& R,
                        std::vector<double>* residuals);
};

// Pure-rotation detection (analogue of COLMAP's H/E inlier-ratio test): on the
// masked correspondences (typically the E inliers) a rotation is fitted
// robustly (deterministic 2-point RANSAC + least-squares refit).  The pair is
// a pure rotation iff the fraction of correspondences with angle(ray2, R ray1)
// <= max_angle_rad is >= min_inlier_ratio.
struct PureRotationResult {
  bool is_pure_rotation = false;
  Eigen::Matrix3d cam2_from_cam1_R = Eigen::Matrix3d::Identity();
  size_t num_inliers = 0;
  double inlier_ratio = 0;
};

PureRotationResult DetectPureRotation(const std::vector<Eigen::Vector3d>& rays1,
                                      const std::vector<Eigen::Vector3d>& rays2,
                                      const std::vector<char>& inlier_mask,
                                      double max_angle_rad,
                                      double min_inlier_ratio = 0.8);

struct RelativePoseRefineOptions {
  // Cauchy loss scale on the angular epipolar residuals [rad]; <= 0: none.
  double loss_scale_rad = 0;
  int max_num_iterations = 100;
};

// Non-linear refinement of cam2_from_cam1 minimising
//   sum_i (theta1_i^2 + theta2_i^2) / 2   (angular epipolar errors)
// over R (quaternion, ceres::QuaternionManifold) and t on the unit sphere
// (ceres::SphereManifold<3>).  t is normalised on input and output.
bool RefineRelativePose(const std::vector<Eigen::Vector3d>& rays1,
                        const std::vector<Eigen::Vector3d>& rays2,
                        const std::vector<char>& inlier_mask,
                        Eigen::Matrix3d* cam2_from_cam1_R,
                        Eigen::Vector3d* cam2_from_cam1_t,
                        const RelativePoseRefineOptions& options =
                            RelativePoseRefineOptions());

}  // namespace sphera
