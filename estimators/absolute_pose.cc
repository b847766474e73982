#include "estimators/absolute_pose.h"

#include <cmath>
#include <limits>

#include <ceres/ceres.h>
#include <opengv/absolute_pose/CentralAbsoluteAdapter.hpp>
#include <opengv/absolute_pose/methods.hpp>

#include "estimators/angular_residual.h"
#include "estimators/solver_options.h"

namespace sphera {
namespace {

// OpenGV pose [R_wc | c] (camera-to-world rotation, centre in world)
// -> cam_from_world [R_wc^T | -R_wc^T c].
Eigen::Matrix3x4d CamFromWorldFromOpenGV(const opengv::transformation_t& T) {
  Eigen::Matrix3x4d cam_from_world;
  const Eigen::Matrix3d R = T.leftCols<3>().transpose();
  cam_from_world.leftCols<3>() = R;
  cam_from_world.col(3) = -R * T.col(3);
  return cam_from_world;
}

bool IsRotation(const Eigen::Matrix3d& R) {
  return R.allFinite() &&
         (R * R.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
         R.determinant() > 0;
}

}  // namespace

double SquaredRayPointAngle(const Eigen::Vector3d& ray,
                            const Eigen::Vector3d& point3D,
                            const Eigen::Matrix3x4d& cam_from_world) {
  const double angle = AngleBetweenRays(
      ray, cam_from_world.leftCols<3>() * point3D + cam_from_world.col(3));
  return angle * angle;
}

void P3PRayEstimator::Estimate(const std::vector<X_t>& rays,
                               const std::vector<Y_t>& points3D,
                               std::vector<M_t>* models) {
  models->clear();
  const size_t n = rays.size();
  if (n < static_cast<size_t>(kMinNumSamples) || points3D.size() != n) return;

  opengv::bearingVectors_t bearings;
  opengv::points_t points;
  bearings.reserve(n);
  points.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    bearings.push_back(rays[i].normalized());
    points.push_back(points3D[i]);
  }
  const opengv::absolute_pose::CentralAbsoluteAdapter adapter(bearings, points);

  if (n == 3) {
    const opengv::transformations_t Ts =
        opengv::absolute_pose::p3p_kneip(adapter);
    for (const auto& T : Ts) {
      if (!T.allFinite()) continue;
      const Eigen::Matrix3x4d cam_from_world = CamFromWorldFromOpenGV(T);
      if (!IsRotation(cam_from_world.leftCols<3>())) continue;
      // Cheirality on the sphere: every sample point in front of its ray.
      bool in_front = true;
      for (size_t i = 0; i < 3; ++i) {
        if (bearings[i].dot(cam_from_world.leftCols<3>() * points3D[i] +
                            cam_from_world.col(3)) <= 0) {
          in_front = false;
        }
      }
      if (in_front) models->push_back(cam_from_world);
    }
    return;
  }

  // Non-minimal: UPnP, best candidate by summed squared angle, then refine.
  const opengv::transformations_t Ts = opengv::absolute_pose::upnp(adapter);
  double best_cost = std::numeric_limits<double>::max();
  Eigen::Matrix3x4d best;
  bool found = false;
  std::vector<double> residuals;
  for (const auto& T : Ts) {
    if (!T.allFinite()) continue;
    const Eigen::Matrix3x4d cam_from_world = CamFromWorldFromOpenGV(T);
    if (!IsRotation(cam_from_world.leftCols<3>())) continue;
    Residuals(rays, points3D, cam_from_world, &residuals);
    double cost = 0;
    for (double r : residuals) cost += r;
    if (cost < best_cost) {
      best_cost = cost;
      best = cam_from_world;
      found = true;
    }
  }
  if (!found) return;
  Eigen::Matrix3x4d refined = best;
  AbsolutePoseRefineOptions options;
  options.max_num_iterations = 20;
  if (RefineAbsolutePose(rays, points3D, {}, &refined, options)) {
    models->push_back(refined);
  } else {
    models->push_back(best);
  }
}

void P3PRayEstimator::Residuals(const std::vector<X_t>& rays,
                                const std::vector<Y_t>& points3D,
                                const M_t& cam_from_world,
                                std::vector<double>* residuals) {
  residuals->resize(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) {
    (*residuals)[i] = SquaredRayPointAngle(rays[i], points3D[i], cam_from_world);
  }
}

bool RefineAbsolutePose(const std::vector<Eigen::Vector3d>& rays,
                        const std::vector<Eigen::Vector3d>& points3D,
                        const std::vector<char>& inlier_mask,
                        Eigen::Matrix3x4d* cam_from_world,
                        const AbsolutePoseRefineOptions& options) {
  const size_t n = rays.size();
  if (points3D.size() != n ||
      (!inlier_mask.empty() && inlier_mask.size() != n)) {
    return false;
  }
  Eigen::Vector4d q =
      RotationMatrixToQuaternionWXYZ(cam_from_world->leftCols<3>());
  Eigen::Vector3d t = cam_from_world->col(3);
  std::vector<Eigen::Vector3d> points = points3D;  // constant blocks

  ceres::Problem problem;
  size_t num_used = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!inlier_mask.empty() && !inlier_mask[i]) continue;
    ceres::LossFunction* loss =
        options.loss_scale_rad > 0 ? new ceres::CauchyLoss(options.loss_scale_rad)
                                   : nullptr;
    problem.AddResidualBlock(AngularReprojectionCost::Create(rays[i]), loss,
                             q.data(), t.data(), points[i].data());
    problem.SetParameterBlockConstant(points[i].data());
    ++num_used;
  }
  if (num_used < 3) return false;
  problem.SetManifold(q.data(), new ceres::QuaternionManifold);

  const ceres::Solver::Options solver_options =
      SmallProblemSolverOptions(options.max_num_iterations);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (!summary.IsSolutionUsable() || !q.allFinite() || !t.allFinite()) {
    return false;
  }
  cam_from_world->leftCols<3>() = QuaternionWXYZToRotationMatrix(q);
  cam_from_world->col(3) = t;
  return true;
}

}  // namespace sphera
