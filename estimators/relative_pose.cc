#include "estimators/relative_pose.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <opengv/relative_pose/CentralRelativeAdapter.hpp>
#include <opengv/relative_pose/methods.hpp>

#include "estimators/angular_residual.h"
#include "estimators/solver_options.h"

namespace sphera {
namespace {

inline bool UseIndex(const std::vector<char>& mask, size_t i) {
  return mask.empty() || mask[i];
}

opengv::bearingVectors_t ToBearings(const std::vector<Eigen::Vector3d>& rays) {
  opengv::bearingVectors_t out;
  out.reserve(rays.size());
  for (const auto& r : rays) out.push_back(r.normalized());
  return out;
}

// Nearest essential matrix (Frobenius): singular values -> (1, 1, 0).
Eigen::Matrix3d ProjectToEssentialManifold(const Eigen::Matrix3d& E) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * Eigen::Vector3d(1, 1, 0).asDiagonal() *
         svd.matrixV().transpose();
}

// Angle between the ray r and the plane with normal n:
// atan2(|n . r|, |n x r|) = asin(|n . r| / (|n| |r|)).
inline double RayPlaneAngle(const Eigen::Vector3d& n, const Eigen::Vector3d& r) {
  return std::atan2(std::abs(n.dot(r)), n.cross(r).norm());
}

// Two-view midpoint triangulation in the camera-1 frame for x2 = R x1 + t:
// least squares for d1 (R r1) - d2 r2 = -t (normal equations, det = |a x b|^2),
// X = (d1 r1 + R^T (d2 r2 - t)) / 2.  Returns false for (near-)parallel rays.
bool TriangulateMidpoint(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                         const Eigen::Vector3d& r1, const Eigen::Vector3d& r2,
                         Eigen::Vector3d* X) {
  const Eigen::Vector3d a = R * r1;
  const Eigen::Vector3d& b = r2;
  const double aa = a.dot(a), bb = b.dot(b), ab = a.dot(b);
  const double at = a.dot(t), bt = b.dot(t);
  const double det = aa * bb - ab * ab;
  if (!(det > 1e-14 * aa * bb)) return false;
  const double d1 = (-at * bb + ab * bt) / det;
  const double d2 = (aa * bt - ab * at) / det;
  *X = 0.5 * (d1 * r1 + R.transpose() * (d2 * r2 - t));
  return X->allFinite();
}

// Ceres cost: signed angular epipolar errors of one correspondence,
// residuals theta1 / sqrt(2), theta2 / sqrt(2), with
//   n2 = t x (R r1),  n1 = R^T (r2 x t)  (= E r1, E^T r2),  e = r2 . n2,
//   theta2 = atan2(e, |n2 x r2|),  theta1 = atan2(e, |n1 x r1|).
// Parameters: q = [w, x, y, z] (4), t (3, unit sphere).
struct AngularEpipolarCost {
  AngularEpipolarCost(const Eigen::Vector3d& r1, const Eigen::Vector3d& r2)
      : r1_(r1.normalized()), r2_(r2.normalized()) {}

  static ceres::CostFunction* Create(const Eigen::Vector3d& r1,
                                     const Eigen::Vector3d& r2) {
    return new ceres::AutoDiffCostFunction<AngularEpipolarCost, 2, 4, 3>(
        new AngularEpipolarCost(r1, r2));
  }

  template <typename T>
  bool operator()(const T* const q, const T* const t, T* residuals) const {
    const T r1[3] = {T(r1_(0)), T(r1_(1)), T(r1_(2))};
    const T r2[3] = {T(r2_(0)), T(r2_(1)), T(r2_(2))};
    T Rr1[3];
    ceres::QuaternionRotatePoint(q, r1, Rr1);
    T n2[3];
    ceres::CrossProduct(t, Rr1, n2);
    const T e = ceres::DotProduct(n2, r2);
    T m[3];
    ceres::CrossProduct(r2, t, m);
    const T q_inv[4] = {q[0], -q[1], -q[2], -q[3]};
    T n1[3];
    ceres::QuaternionRotatePoint(q_inv, m, n1);
    T c2[3], c1[3];
    ceres::CrossProduct(n2, r2, c2);
    ceres::CrossProduct(n1, r1, c1);
    using std::atan2;
    using std::sqrt;
    const T s2 = sqrt(ceres::DotProduct(c2, c2));
    const T s1 = sqrt(ceres::DotProduct(c1, c1));
    const T inv_sqrt2 = T(1.0 / std::sqrt(2.0));
    residuals[0] = inv_sqrt2 * atan2(e, s1);
    residuals[1] = inv_sqrt2 * atan2(e, s2);
    return true;
  }

  Eigen::Vector3d r1_, r2_;
};

}  // namespace

Eigen::Matrix3d EssentialMatrixFromPose(const Eigen::Matrix3d& cam2_from_cam1_R,
                                        const Eigen::Vector3d& cam2_from_cam1_t) {
  Eigen::Matrix3d tx;
  const Eigen::Vector3d& t = cam2_from_cam1_t;
  tx << 0, -t(2), t(1), t(2), 0, -t(0), -t(1), t(0), 0;
  return tx * cam2_from_cam1_R;
}

double SquaredAngularEpipolarError(const Eigen::Matrix3d& E,
                                   const Eigen::Vector3d& ray1,
                                   const Eigen::Vector3d& ray2) {
  const double theta2 = RayPlaneAngle(E * ray1, ray2);
  const double theta1 = RayPlaneAngle(E.transpose() * ray2, ray1);
  return 0.5 * (theta1 * theta1 + theta2 * theta2);
}

void EssentialMatrixRayEstimator::Estimate(const std::vector<X_t>& rays1,
                                           const std::vector<Y_t>& rays2,
                                           std::vector<M_t>* models) {
  models->clear();
  const size_t n = rays1.size();
  if (n < static_cast<size_t>(kMinNumSamples) || rays2.size() != n) return;
  const opengv::bearingVectors_t b1 = ToBearings(rays1);
  const opengv::bearingVectors_t b2 = ToBearings(rays2);
  const opengv::relative_pose::CentralRelativeAdapter adapter(b1, b2);
  // OpenGV: f1^T E_gv f2 = 0; ours: r2^T E r1 = 0, so E = E_gv^T.
  if (n < 8) {
    // Stewenius' 5-point solver (Groebner basis + 10x10 eigenproblem; with
    // 6-7 rays the 4-dim null space is the least-squares one).  It returns
    // all 10 (complex) roots; the real ones are kept.  On random full-sphere
    // configurations it finds the true E in 100% of cases where OpenGV's
    // fivept_nister does so in ~94%.
    const opengv::complexEssentials_t Es =
        opengv::relative_pose::fivept_stewenius(adapter);
    for (const auto& E_c : Es) {
      const Eigen::Matrix3d E_gv = E_c.real();
      const double norm = E_gv.norm();
      if (!E_gv.allFinite() || !(norm > 0) ||
          E_c.imag().norm() > 1e-8 * norm) {
        continue;
      }
      models->push_back(E_gv.transpose() / norm);
    }
  } else {
    const opengv::essential_t E_gv = opengv::relative_pose::eightpt(adapter);
    if (E_gv.allFinite() && E_gv.norm() > 0) {
      models->push_back(ProjectToEssentialManifold(E_gv.transpose()));
    }
  }
}

void EssentialMatrixRayEstimator::Residuals(const std::vector<X_t>& rays1,
                                            const std::vector<Y_t>& rays2,
                                            const M_t& E,
                                            std::vector<double>* residuals) {
  residuals->resize(rays1.size());
  for (size_t i = 0; i < rays1.size(); ++i) {
    (*residuals)[i] = SquaredAngularEpipolarError(E, rays1[i], rays2[i]);
  }
}

void DecomposeEssentialMatrix(const Eigen::Matrix3d& E, Eigen::Matrix3d* R1,
                              Eigen::Matrix3d* R2, Eigen::Vector3d* t) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  Eigen::Matrix3d V = svd.matrixV();
  // E ~ U diag(1,1,0) V^T is unchanged (up to sign) by flipping the third
  // column of U or V, which makes both proper rotations.
  if (U.determinant() < 0) U.col(2) *= -1;
  if (V.determinant() < 0) V.col(2) *= -1;
  Eigen::Matrix3d W;
  W << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  *R1 = U * W * V.transpose();
  *R2 = U * W.transpose() * V.transpose();
  *t = U.col(2).normalized();
}

size_t RelativePoseFromEssential(const Eigen::Matrix3d& E,
                                 const std::vector<Eigen::Vector3d>& rays1,
                                 const std::vector<Eigen::Vector3d>& rays2,
                                 const std::vector<char>& inlier_mask,
                                 Eigen::Matrix3d* cam2_from_cam1_R,
                                 Eigen::Vector3d* cam2_from_cam1_t,
                                 std::vector<Eigen::Vector3d>* points3D,
                                 std::vector<char>* point_mask) {
  const size_t n = rays1.size();
  if (points3D) points3D->clear();
  if (point_mask) point_mask->assign(n, 0);
  if (!E.allFinite() || rays2.size() != n ||
      (!inlier_mask.empty() && inlier_mask.size() != n)) {
    return 0;
  }
  Eigen::Matrix3d R1, R2;
  Eigen::Vector3d t;
  DecomposeEssentialMatrix(E, &R1, &R2, &t);
  const Eigen::Matrix3d Rs[4] = {R1, R2, R1, R2};
  const Eigen::Vector3d ts[4] = {t, t, -t, -t};

  // |t| = 1, so the depth bound is 1000 (COLMAP uses 1000 * baseline).
  const double kMaxDepth = 1000.0;
  size_t best_count = 0;
  int best = -1;
  std::vector<Eigen::Vector3d> best_points;
  std::vector<char> best_mask;
  for (int k = 0; k < 4; ++k) {
    std::vector<Eigen::Vector3d> points;
    std::vector<char> mask(n, 0);
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
      if (!UseIndex(inlier_mask, i)) continue;
      const Eigen::Vector3d r1 = rays1[i].normalized();
      const Eigen::Vector3d r2 = rays2[i].normalized();
      Eigen::Vector3d X;
      if (!TriangulateMidpoint(Rs[k], ts[k], r1, r2, &X)) continue;
      const double depth1 = r1.dot(X);
      const double depth2 = r2.dot(Rs[k] * X + ts[k]);
      if (depth1 > 0 && depth2 > 0 && depth1 < kMaxDepth &&
          depth2 < kMaxDepth) {
        ++count;
        mask[i] = 1;
        if (points3D) points.push_back(X);
      }
    }
    if (count > best_count) {
      best_count = count;
      best = k;
      best_points.swap(points);
      best_mask.swap(mask);
    }
  }
  if (best < 0) return 0;
  *cam2_from_cam1_R = Rs[best];
  *cam2_from_cam1_t = ts[best];
  if (points3D) points3D->swap(best_points);
  if (point_mask) point_mask->swap(best_mask);
  return best_count;
}

void RotationOnlyEstimator::Estimate(const std::vector<X_t>& rays1,
                                     const std::vector<Y_t>& rays2,
                                     std::vector<M_t>* models) {
  models->clear();
  const size_t n = rays1.size();
  if (n < static_cast<size_t>(kMinNumSamples) || rays2.size() != n) return;
  // Uncentred Kabsch / Wahba: maximise sum_i r2_i . (R r1_i) = tr(R^T H),
  // H = sum_i r2_i r1_i^T = U S V^T  =>  R = U diag(1, 1, det(U V^T)) V^T.
  // (OpenGV's rotationOnly centres the bearings first, which is the
  // point-cloud model and is rank deficient for 2 rays; directions related
  // by a pure rotation must not be centred.)  2 non-parallel rays give
  // rank(H) = 2, enough for a unique R after the determinant correction.
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    H += rays2[i].normalized() * rays1[i].normalized().transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d& sv = svd.singularValues();
  if (!(sv(1) > 1e-12 * sv(0))) return;  // all rays parallel: degenerate
  Eigen::Vector3d d(1, 1, 1);
  d(2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() > 0 ? 1 : -1;
  const Eigen::Matrix3d R =
      svd.matrixU() * d.asDiagonal() * svd.matrixV().transpose();
  if (!R.allFinite()) return;
  models->push_back(R);
}

void RotationOnlyEstimator::Residuals(const std::vector<X_t>& rays1,
                                      const std::vector<Y_t>& rays2,
                                      const M_t& R,
                                      std::vector<double>* residuals) {
  residuals->resize(rays1.size());
  for (size_t i = 0; i < rays1.size(); ++i) {
    const double angle = AngleBetweenRays(rays2[i], R * rays1[i]);
    (*residuals)[i] = angle * angle;
  }
}

PureRotationResult DetectPureRotation(const std::vector<Eigen::Vector3d>& rays1,
                                      const std::vector<Eigen::Vector3d>& rays2,
                                      const std::vector<char>& inlier_mask,
                                      double max_angle_rad,
                                      double min_inlier_ratio) {
  PureRotationResult result;
  std::vector<Eigen::Vector3d> r1, r2;
  for (size_t i = 0; i < rays1.size() && i < rays2.size(); ++i) {
    if (UseIndex(inlier_mask, i)) {
      r1.push_back(rays1[i]);
      r2.push_back(rays2[i]);
    }
  }
  const size_t n = r1.size();
  if (n < 2) return result;
  const double max_sq = max_angle_rad * max_angle_rad;

  auto count_inliers = [&](const Eigen::Matrix3d& R, std::vector<char>* mask) {
    std::vector<double> res;
    RotationOnlyEstimator::Residuals(r1, r2, R, &res);
    size_t c = 0;
    if (mask) mask->assign(n, 0);
    for (size_t i = 0; i < n; ++i) {
      if (res[i] <= max_sq) {
        ++c;
        if (mask) (*mask)[i] = 1;
      }
    }
    return c;
  };

  // Deterministic 2-point RANSAC.
  std::mt19937 rng(0);
  std::uniform_int_distribution<size_t> dist(0, n - 1);
  Eigen::Matrix3d best_R = Eigen::Matrix3d::Identity();
  size_t best = 0;
  const int kNumTrials = 200;
  std::vector<Eigen::Vector3d> s1(2), s2(2);
  std::vector<Eigen::Matrix3d> models;
  for (int trial = 0; trial < kNumTrials; ++trial) {
    const size_t i = dist(rng);
    size_t j = dist(rng);
    if (n > 1) {
      while (j == i) j = dist(rng);
    }
    s1[0] = r1[i]; s1[1] = r1[j];
    s2[0] = r2[i]; s2[1] = r2[j];
    RotationOnlyEstimator::Estimate(s1, s2, &models);
    for (const auto& R : models) {
      const size_t c = count_inliers(R, nullptr);
      if (c > best) {
        best = c;
        best_R = R;
      }
    }
    if (best == n) break;
  }
  // Least-squares refit on the inliers (twice).
  for (int it = 0; it < 2 && best >= 2; ++it) {
    std::vector<char> mask;
    count_inliers(best_R, &mask);
    std::vector<Eigen::Vector3d> i1, i2;
    for (size_t i = 0; i < n; ++i) {
      if (mask[i]) {
        i1.push_back(r1[i]);
        i2.push_back(r2[i]);
      }
    }
    RotationOnlyEstimator::Estimate(i1, i2, &models);
    if (models.empty()) break;
    const size_t c = count_inliers(models[0], nullptr);
    if (c < best) break;
    best = c;
    best_R = models[0];
  }
  result.cam2_from_cam1_R = best_R;
  result.num_inliers = best;
  result.inlier_ratio = static_cast<double>(best) / static_cast<double>(n);
  result.is_pure_rotation = result.inlier_ratio >= min_inlier_ratio;
  return result;
}

bool RefineRelativePose(const std::vector<Eigen::Vector3d>& rays1,
                        const std::vector<Eigen::Vector3d>& rays2,
                        const std::vector<char>& inlier_mask,
                        Eigen::Matrix3d* cam2_from_cam1_R,
                        Eigen::Vector3d* cam2_from_cam1_t,
                        const RelativePoseRefineOptions& options) {
  const size_t n = rays1.size();
  if (rays2.size() != n || (!inlier_mask.empty() && inlier_mask.size() != n)) {
    return false;
  }
  if (!(cam2_from_cam1_t->norm() > 0)) return false;
  Eigen::Vector4d q = RotationMatrixToQuaternionWXYZ(*cam2_from_cam1_R);
  Eigen::Vector3d t = cam2_from_cam1_t->normalized();

  ceres::Problem problem;
  size_t num_residuals = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!UseIndex(inlier_mask, i)) continue;
    ceres::LossFunction* loss =
        options.loss_scale_rad > 0 ? new ceres::CauchyLoss(options.loss_scale_rad)
                                   : nullptr;
    problem.AddResidualBlock(AngularEpipolarCost::Create(rays1[i], rays2[i]),
                             loss, q.data(), t.data());
    ++num_residuals;
  }
  if (num_residuals < 5) return false;
  problem.SetManifold(q.data(), new ceres::QuaternionManifold);
  problem.SetManifold(t.data(), new ceres::SphereManifold<3>);

  const ceres::Solver::Options solver_options =
      SmallProblemSolverOptions(options.max_num_iterations);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (!summary.IsSolutionUsable() || !q.allFinite() || !t.allFinite()) {
    return false;
  }
  *cam2_from_cam1_R = QuaternionWXYZToRotationMatrix(q);
  *cam2_from_cam1_t = t.normalized();
  return true;
}

}  // namespace sphera
