#include "estimators/triangulation.h"

#include <cmath>
#include <limits>

#include <Eigen/SVD>
#include <ceres/ceres.h>

#include "estimators/angular_residual.h"
#include "estimators/solver_options.h"

namespace sphera {

std::optional<Eigen::Vector3d> TriangulateRays(
    const std::vector<Eigen::Matrix3x4d>& cams_from_world,
    const std::vector<Eigen::Vector3d>& rays) {
  const size_t n = cams_from_world.size();
  if (n < 2 || rays.size() != n) return std::nullopt;

  // Conditioning: X = c_mean + s Y with c_mean the mean camera centre and s
  // the mean distance of the centres to it.  Then
  //   R_i X + t_i = s (R_i Y + t'_i),  t'_i = (R_i c_mean + t_i) / s,
  // and the (homogeneous) ray constraints are solved for Y.
  Eigen::Vector3d c_mean = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> centers(n);
  for (size_t i = 0; i < n; ++i) {
    centers[i] = ProjectionCenter(cams_from_world[i]);
    c_mean += centers[i];
  }
  c_mean /= static_cast<double>(n);
  double scale = 0;
  for (size_t i = 0; i < n; ++i) scale += (centers[i] - c_mean).norm();
  scale /= static_cast<double>(n);
  if (!(scale > 0)) return std::nullopt;  // all centres coincide

  Eigen::MatrixXd A(2 * n, 4);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Matrix3d R = cams_from_world[i].leftCols<3>();
    const Eigen::Vector3d t =
        (R * c_mean + cams_from_world[i].col(3)) / scale;
    const Eigen::Vector3d u = rays[i].normalized();
    Eigen::Vector3d e1, e2;
    RayTangentBasis(u, &e1, &e2);
    A.block<1, 3>(2 * i, 0) = e1.transpose() * R;
    A(2 * i, 3) = e1.dot(t);
    A.block<1, 3>(2 * i + 1, 0) = e2.transpose() * R;
    A(2 * i + 1, 3) = e2.dot(t);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d Y_h = svd.matrixV().col(3);
  if (std::abs(Y_h(3)) <= std::numeric_limits<double>::epsilon() *
                              Y_h.head<3>().norm()) {
    return std::nullopt;  // point at infinity
  }
  const Eigen::Vector3d X = c_mean + scale * Y_h.head<3>() / Y_h(3);
  if (!X.allFinite()) return std::nullopt;
  return X;
}

Eigen::Vector3d ProjectionCenter(const Eigen::Matrix3x4d& cam_from_world) {
  return -cam_from_world.leftCols<3>().transpose() * cam_from_world.col(3);
}

double RayAngularError(const Eigen::Vector3d& ray,
                       const Eigen::Matrix3x4d& cam_from_world,
                       const Eigen::Vector3d& point3D) {
  return AngleBetweenRays(ray, cam_from_world.leftCols<3>() * point3D +
                                   cam_from_world.col(3));
}

bool HasPositiveRayDepth(const Eigen::Vector3d& ray,
                         const Eigen::Matrix3x4d& cam_from_world,
                         const Eigen::Vector3d& point3D) {
  return ray.dot(cam_from_world.leftCols<3>() * point3D +
                 cam_from_world.col(3)) > 0;
}

bool CheckRayCheirality(const std::vector<Eigen::Matrix3x4d>& cams_from_world,
                        const std::vector<Eigen::Vector3d>& rays,
                        const Eigen::Vector3d& point3D) {
  if (cams_from_world.size() != rays.size()) return false;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (!HasPositiveRayDepth(rays[i], cams_from_world[i], point3D)) {
      return false;
    }
  }
  return true;
}

bool RefineTriangulatedPoint(
    const std::vector<Eigen::Matrix3x4d>& cams_from_world,
    const std::vector<Eigen::Vector3d>& rays, Eigen::Vector3d* point3D,
    int max_num_iterations) {
  if (cams_from_world.size() != rays.size() || rays.size() < 2) return false;
  ceres::Problem problem;
  for (size_t i = 0; i < rays.size(); ++i) {
    problem.AddResidualBlock(
        AngularReprojectionConstantPoseCost::Create(
            rays[i], cams_from_world[i].leftCols<3>(),
            cams_from_world[i].col(3)),
        nullptr, point3D->data());
  }
  const ceres::Solver::Options options =
      SmallProblemSolverOptions(max_num_iterations);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return summary.IsSolutionUsable() && point3D->allFinite();
}

}  // namespace sphera
