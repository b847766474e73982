#include "estimators/camera_only_bundle_adjustment.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include "estimators/angular_residual.h"
#include "estimators/triangulation.h"

namespace sphera {

Eigen::Matrix3x4d CameraPose::Matrix() const {
  Eigen::Matrix3x4d P;
  P.leftCols<3>() = rotation.normalized().toRotationMatrix();
  P.col(3) = translation;
  return P;
}

const char* CameraOnlyBAStatusName(CameraOnlyBAStatus status) {
  switch (status) {
    case CameraOnlyBAStatus::kSuccess:
      return "success";
    case CameraOnlyBAStatus::kInvalidInput:
      return "invalid input";
    case CameraOnlyBAStatus::kTooFewObservations:
      return "too few observations per camera";
    case CameraOnlyBAStatus::kNoReliablePoints:
      return "no reliable points (tau below the noise floor)";
    case CameraOnlyBAStatus::kDegenerateGeometry:
      return "degenerate geometry";
    case CameraOnlyBAStatus::kSolverFailure:
      return "solver failure";
  }
  return "unknown";
}

namespace {

// Angular residual of a world point X in a camera parametrised by its
// rotation q (Eigen order [x, y, z, w]) and its centre C = offset + scale * c:
//   r = Log_u(R(q) (X - C)),  |r| = angle(u, R (X - C)).
class PoseCenterAngularCost {
 public:
  PoseCenterAngularCost(const Eigen::Vector3d& ray,
                        const Eigen::Vector3d& offset, double scale)
      : u_(ray.normalized()), offset_(offset), scale_(scale) {
    RayTangentBasis(u_, &e1_, &e2_);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& ray,
                                     const Eigen::Vector3d& offset,
                                     double scale) {
    return new ceres::AutoDiffCostFunction<PoseCenterAngularCost, 2, 4, 3, 3>(
        new PoseCenterAngularCost(ray, offset, scale));
  }

  template <typename T>
  bool operator()(const T* const q_xyzw, const T* const c, const T* const X,
                  T* residuals) const {
    T d[3];
    for (int k = 0; k < 3; ++k) {
      d[k] = X[k] - (T(offset_(k)) + T(scale_) * c[k]);
    }
    const T q_wxyz[4] = {q_xyzw[3], q_xyzw[0], q_xyzw[1], q_xyzw[2]};
    T v[3];
    ceres::QuaternionRotatePoint(q_wxyz, d, v);
    const T a = T(e1_(0)) * v[0] + T(e1_(1)) * v[1] + T(e1_(2)) * v[2];
    const T b = T(e2_(0)) * v[0] + T(e2_(1)) * v[1] + T(e2_(2)) * v[2];
    const T cc = T(u_(0)) * v[0] + T(u_(1)) * v[1] + T(u_(2)) * v[2];
    LogMapResidualFromComponents(a, b, cc, residuals);
    return true;
  }

 private:
  Eigen::Vector3d u_, e1_, e2_, offset_;
  double scale_;
};

double Rho(const CameraOnlyBAOptions& options, double s) {
  if (options.loss == CameraOnlyBALoss::kCauchy) {
    const double b = options.loss_scale_rad * options.loss_scale_rad;
    return b * std::log1p(s / b);
  }
  return s;
}

std::string Fmt(const char* fmt, double v) {
  char buf[128];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

// Per-image tau [rad] for this iteration, or an error message (and the
// image it concerns, or -1).
bool EvaluateTau(const CameraOnlyBAOptions& options, int num_images,
                 std::vector<double>* tau, std::string* message,
                 int* image_idx) {
  *image_idx = -1;
  tau->assign(num_images, 0);
  for (int i = 0; i < num_images; ++i) {
    double t;
    if (options.tau_rad_fn) {
      t = options.tau_rad_fn(i);
    } else if (options.tau_rad.size() == 1) {
      t = options.tau_rad[0];
    } else if (static_cast<int>(options.tau_rad.size()) == num_images) {
      t = options.tau_rad[i];
    } else {
      *message = "tau_rad must have one entry or one per image (" +
                 std::to_string(num_images) + "), got " +
                 std::to_string(options.tau_rad.size());
      return false;
    }
    if (!(t > 0) || !std::isfinite(t)) {
      *message = "tau_rad must be finite and > 0, got " + Fmt("%g", t);
      *image_idx = i;
      return false;
    }
    (*tau)[i] = t;
  }
  return true;
}

double SceneScale(const std::vector<CameraPose>& poses) {
  if (poses.empty()) return 1;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : poses) mean += p.Center();
  mean /= static_cast<double>(poses.size());
  double s = 0;
  for (const auto& p : poses) s += (p.Center() - mean).norm();
  s /= static_cast<double>(poses.size());
  return s > 0 ? s : 1;
}

// Smallest / largest eigenvalue of the scale-normalised 6x6 normal matrix of
// the pose of one camera with its reliable points fixed (left rotation
// perturbation, centre perturbation times the median depth).
double PoseConditioning(const CameraPose& pose,
                        const std::vector<Eigen::Vector3d>& rays,
                        const std::vector<Eigen::Vector3d>& points) {
  if (rays.empty()) return 0;
  const Eigen::Matrix3d R = pose.rotation.normalized().toRotationMatrix();
  const Eigen::Vector3d C = pose.Center();
  std::vector<double> depths;
  depths.reserve(points.size());
  for (const auto& X : points) depths.push_back((R * (X - C)).norm());
  std::vector<double> sorted = depths;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2,
                   sorted.end());
  const double median_depth = sorted[sorted.size() / 2];
  if (!(median_depth > 0)) return 0;
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  for (size_t k = 0; k < rays.size(); ++k) {
    const Eigen::Vector3d v = R * (points[k] - C);
    const double depth = v.norm();
    if (!(depth > 0)) continue;
    const Eigen::Vector3d f = v / depth;
    Eigen::Vector3d e1, e2;
    const Eigen::Vector3d u = rays[k].normalized();
    RayTangentBasis(u, &e1, &e2);
    Eigen::Matrix<double, 2, 3> B;
    B.row(0) = e1.transpose();
    B.row(1) = e2.transpose();
    Eigen::Matrix3d fx;
    fx << 0, -f(2), f(1), f(2), 0, -f(0), -f(1), f(0), 0;
    Eigen::Matrix<double, 2, 6> J;
    J.leftCols<3>() = -B * fx;
    J.rightCols<3>() = -B * R * (median_depth / depth);
    H += J.transpose() * J;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(H);
  const double max_ev = es.eigenvalues().maxCoeff();
  if (!(max_ev > 0)) return 0;
  return std::max(0.0, es.eigenvalues().minCoeff()) / max_ev;
}

struct ObservationRef {  // an observation of a reliable point
  int point_idx;
  int obs_idx;  // index in the track
};

}  // namespace

std::vector<ReliablePoint> TriangulateReliablePoints(
    const std::vector<CameraPose>& poses, const std::vector<RayTrack>& tracks,
    const std::vector<double>& tau_rad, bool refine_points,
    int max_num_point_iterations, int* num_triangulated) {
  std::vector<Eigen::Matrix3x4d> matrices(poses.size());
  for (size_t i = 0; i < poses.size(); ++i) matrices[i] = poses[i].Matrix();
  std::vector<ReliablePoint> points;
  int triangulated = 0;
  std::vector<Eigen::Matrix3x4d> cams;
  std::vector<Eigen::Vector3d> rays;
  for (size_t j = 0; j < tracks.size(); ++j) {
    const RayTrack& track = tracks[j];
    if (track.size() < 2) continue;
    cams.clear();
    rays.clear();
    for (const auto& obs : track) {
      cams.push_back(matrices[obs.image_idx]);
      rays.push_back(obs.ray);
    }
    std::optional<Eigen::Vector3d> X = TriangulateRays(cams, rays);
    if (!X) continue;
    if (refine_points) {
      Eigen::Vector3d Xr = *X;
      if (RefineTriangulatedPoint(cams, rays, &Xr, max_num_point_iterations)) {
        X = Xr;
      }
    }
    if (!CheckRayCheirality(cams, rays, *X)) continue;
    ++triangulated;
    ReliablePoint point;
    point.track_idx = static_cast<int>(j);
    point.xyz = *X;
    point.errors_rad.resize(track.size());
    bool reliable = true;
    for (size_t k = 0; k < track.size(); ++k) {
      point.errors_rad[k] = RayAngularError(rays[k], cams[k], *X);
      if (!(point.errors_rad[k] <= tau_rad[track[k].image_idx])) {
        reliable = false;
      }
    }
    if (reliable) points.push_back(std::move(point));
  }
  if (num_triangulated) *num_triangulated = triangulated;
  return points;
}

CameraOnlyBAResult CameraOnlyBundleAdjustment(
    const CameraOnlyBAProblem& problem, const CameraOnlyBAOptions& options) {
  const auto t_start = std::chrono::steady_clock::now();
  CameraOnlyBAResult result;
  result.poses = problem.poses;
  auto finish = [&](CameraOnlyBAStatus status, const std::string& message,
                    int image_idx = -1) {
    result.status = status;
    result.message = message;
    result.image_idx = image_idx;
    result.elapsed_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                      t_start)
            .count();
    return result;
  };

  // ---- Validation ------------------------------------------------------
  const int num_images = static_cast<int>(problem.poses.size());
  if (num_images < 1) {
    return finish(CameraOnlyBAStatus::kInvalidInput, "no cameras (poses)");
  }
  if (options.max_iterations < 1) {
    return finish(CameraOnlyBAStatus::kInvalidInput,
                  "max_iterations must be >= 1");
  }
  if (options.loss == CameraOnlyBALoss::kCauchy &&
      !(options.loss_scale_rad > 0)) {
    return finish(CameraOnlyBAStatus::kInvalidInput,
                  "loss_scale_rad must be > 0 for the Cauchy loss");
  }
  std::vector<CameraPose> poses = problem.poses;
  for (int i = 0; i < num_images; ++i) {
    if (!poses[i].rotation.coeffs().allFinite() ||
        !(poses[i].rotation.norm() > 0) ||
        !poses[i].translation.allFinite()) {
      return finish(CameraOnlyBAStatus::kInvalidInput,
                    "pose of image " + std::to_string(i) + " is not finite");
    }
    poses[i].rotation.normalize();
  }
  std::vector<RayTrack> tracks = problem.tracks;
  std::vector<int> num_obs_per_image(num_images, 0);
  for (size_t j = 0; j < tracks.size(); ++j) {
    for (auto& obs : tracks[j]) {
      if (obs.image_idx < 0 || obs.image_idx >= num_images) {
        return finish(CameraOnlyBAStatus::kInvalidInput,
                      "track " + std::to_string(j) +
                          " refers to an unknown image index " +
                          std::to_string(obs.image_idx));
      }
      if (!obs.ray.allFinite() || !(obs.ray.norm() > 0)) {
        return finish(CameraOnlyBAStatus::kInvalidInput,
                      "track " + std::to_string(j) +
                          " has a zero or non-finite ray");
      }
      obs.ray.normalize();
      if (tracks[j].size() >= 2) ++num_obs_per_image[obs.image_idx];
    }
  }
  std::vector<double> tau;
  std::string tau_message;
  int tau_image = -1;
  if (!EvaluateTau(options, num_images, &tau, &tau_message, &tau_image)) {
    return finish(CameraOnlyBAStatus::kInvalidInput, tau_message, tau_image);
  }
  for (int i = 0; i < num_images; ++i) {
    if (num_obs_per_image[i] < options.min_observations_per_image) {
      return finish(
          CameraOnlyBAStatus::kTooFewObservations,
          "observes only " + std::to_string(num_obs_per_image[i]) +
              " points of tracks with >= 2 observations "
              "(min_observations_per_image = " +
              std::to_string(options.min_observations_per_image) + ")",
          i);
    }
  }
  const int g0 = options.gauge_image0;
  const int g1 = options.gauge_image1;
  double gauge_distance = 0;
  const double scene_scale = SceneScale(poses);
  if (num_images < 2 || g0 < 0 || g1 < 0 || g0 >= num_images ||
      g1 >= num_images || g0 == g1) {
    return finish(CameraOnlyBAStatus::kInvalidInput,
                  "gauge_image0/gauge_image1 must be two distinct images");
  }
  gauge_distance = (poses[g1].Center() - poses[g0].Center()).norm();
  if (!(gauge_distance > 1e-9 * scene_scale)) {
    return finish(CameraOnlyBAStatus::kDegenerateGeometry,
                  "the gauge cameras " + std::to_string(g0) + " and " +
                      std::to_string(g1) + " share their centre (baseline " +
                      Fmt("%g", gauge_distance) +
                      "): the scale cannot be fixed");
  }

  // ---- Outer iterations ------------------------------------------------
  for (int iter = 1; iter <= options.max_iterations; ++iter) {
    if (!EvaluateTau(options, num_images, &tau, &tau_message, &tau_image)) {
      return finish(CameraOnlyBAStatus::kInvalidInput, tau_message,
                    tau_image);
    }
    int num_triangulated = 0;
    std::vector<ReliablePoint> points = TriangulateReliablePoints(
        poses, tracks, tau, options.refine_points,
        options.max_num_point_iterations, &num_triangulated);
    if (num_triangulated == 0) {
      return finish(CameraOnlyBAStatus::kDegenerateGeometry,
                    "no track could be triangulated (camera centres "
                    "coincide or rays are parallel)");
    }
    if (points.empty()) {
      return finish(
          CameraOnlyBAStatus::kNoReliablePoints,
          "tau is below the noise floor: none of the " +
              std::to_string(num_triangulated) +
              " triangulated tracks has every observation within tau "
              "(smallest tau " +
              Fmt("%.3g", *std::min_element(tau.begin(), tau.end())) +
              " rad); increase tau");
    }

    // Observations of the reliable points per image.
    std::vector<std::vector<ObservationRef>> refs(num_images);
    for (size_t p = 0; p < points.size(); ++p) {
      const RayTrack& track = tracks[points[p].track_idx];
      for (size_t k = 0; k < track.size(); ++k) {
        refs[track[k].image_idx].push_back(
            {static_cast<int>(p), static_cast<int>(k)});
      }
    }
    for (int i = 0; i < num_images; ++i) {
      if (i == g0) continue;
      if (static_cast<int>(refs[i].size()) <
          options.min_observations_per_image) {
        return finish(
            CameraOnlyBAStatus::kTooFewObservations,
            "keeps only " + std::to_string(refs[i].size()) +
                " reliable observations within tau (" +
                Fmt("%.3g", tau[i]) + " rad; min_observations_per_image = " +
                std::to_string(options.min_observations_per_image) +
                "); increase tau",
            i);
      }
      std::vector<Eigen::Vector3d> rays, X;
      for (const auto& ref : refs[i]) {
        rays.push_back(tracks[points[ref.point_idx].track_idx][ref.obs_idx].ray);
        X.push_back(points[ref.point_idx].xyz);
      }
      const double cond = PoseConditioning(poses[i], rays, X);
      if (!(cond >= options.min_pose_conditioning)) {
        return finish(CameraOnlyBAStatus::kDegenerateGeometry,
                      "the pose of image " + std::to_string(i) +
                          " is not determined by its " +
                          std::to_string(rays.size()) +
                          " reliable points (normal matrix conditioning " +
                          Fmt("%.3g", cond) + ")");
      }
    }

    CameraOnlyBAIterationStats stats;
    stats.iteration = iter;
    stats.num_reliable_points = static_cast<int>(points.size());
    double sum_err = 0;
    int n_obs = 0;
    for (const auto& p : points) {
      for (const double e : p.errors_rad) {
        sum_err += e;
        stats.cost_before += 0.5 * Rho(options, e * e);
        ++n_obs;
      }
    }
    stats.num_reliable_observations = n_obs;
    stats.mean_error_before_rad = sum_err / n_obs;
    if (iter == 1) result.initial_mean_error_rad = stats.mean_error_before_rad;

    // ---- Pose step (Eq. 6) over the reliable points. ----
    // The points enter as functions of the poses: they are nuisance blocks,
    // eliminated by the Schur complement in every Gauss-Newton step
    // (variable projection), then discarded; the next iteration
    // re-triangulates them from the new poses.
    std::vector<Eigen::Vector4d> qs(num_images);
    std::vector<Eigen::Vector3d> cs(num_images);
    std::vector<Eigen::Vector3d> offsets(num_images, Eigen::Vector3d::Zero());
    std::vector<double> scales(num_images, 1.0);
    for (int i = 0; i < num_images; ++i) {
      qs[i] = poses[i].rotation.coeffs();  // x, y, z, w
      cs[i] = poses[i].Center();
      if (i == g1) {
        offsets[i] = poses[g0].Center();
        scales[i] = gauge_distance;
        cs[i] = (cs[i] - offsets[i]) / scales[i];
      }
    }
    std::vector<Eigen::Vector3d> xyz(points.size());
    for (size_t p = 0; p < points.size(); ++p) xyz[p] = points[p].xyz;
    {
      ceres::Problem ceres_problem;
      auto* ordering = new ceres::ParameterBlockOrdering;
      for (size_t p = 0; p < points.size(); ++p) {
        const RayTrack& track = tracks[points[p].track_idx];
        for (const auto& obs : track) {
          const int i = obs.image_idx;
          ceres::LossFunction* loss =
              options.loss == CameraOnlyBALoss::kCauchy
                  ? new ceres::CauchyLoss(options.loss_scale_rad)
                  : nullptr;
          ceres_problem.AddResidualBlock(
              PoseCenterAngularCost::Create(obs.ray, offsets[i], scales[i]),
              loss, qs[i].data(), cs[i].data(), xyz[p].data());
        }
        ordering->AddElementToGroup(xyz[p].data(), 0);
      }
      for (int i = 0; i < num_images; ++i) {
        if (!ceres_problem.HasParameterBlock(qs[i].data())) continue;
        ceres_problem.SetManifold(qs[i].data(),
                                  new ceres::EigenQuaternionManifold);
        if (i == g0) {
          ceres_problem.SetParameterBlockConstant(qs[i].data());
          ceres_problem.SetParameterBlockConstant(cs[i].data());
        } else if (i == g1) {
          ceres_problem.SetManifold(cs[i].data(), new ceres::SphereManifold<3>);
        }
        ordering->AddElementToGroup(qs[i].data(), 1);
        ordering->AddElementToGroup(cs[i].data(), 1);
      }
      ceres::Solver::Options solver_options;
      const bool sparse = ceres::IsSparseLinearAlgebraLibraryTypeAvailable(
          ceres::SUITE_SPARSE);
      solver_options.linear_solver_type =
          sparse && num_images > 50 ? ceres::SPARSE_SCHUR : ceres::DENSE_SCHUR;
      solver_options.linear_solver_ordering.reset(ordering);
      solver_options.max_num_iterations = options.max_num_pose_iterations;
      // Tight, but above the round-off of the cost (a tighter tolerance
      // ends in "invalid steps" at the optimum).
      solver_options.function_tolerance = 1e-14;
      solver_options.gradient_tolerance = 1e-20;
      solver_options.parameter_tolerance = 1e-14;
      solver_options.num_threads = std::max(1, options.num_threads);
      solver_options.logging_type = ceres::SILENT;
      ceres::Solver::Summary summary;
      ceres::Solve(solver_options, &ceres_problem, &summary);
      // Ceres keeps the last accepted state; a FAILURE termination after
      // repeated invalid steps at the optimum (round-off) is still usable.
      bool finite = true;
      for (int i = 0; i < num_images; ++i) {
        finite = finite && qs[i].allFinite() && cs[i].allFinite();
      }
      for (const auto& X : xyz) finite = finite && X.allFinite();
      if (!finite ||
          !(summary.final_cost <= summary.initial_cost * (1 + 1e-12))) {
        return finish(CameraOnlyBAStatus::kSolverFailure,
                      "the pose step failed: " + summary.BriefReport());
      }
    }
    std::vector<CameraPose> new_poses = poses;
    for (int i = 0; i < num_images; ++i) {
      if (i == g0) continue;
      CameraPose& pose = new_poses[i];
      pose.rotation =
          Eigen::Quaterniond(qs[i](3), qs[i](0), qs[i](1), qs[i](2))
              .normalized();
      const Eigen::Vector3d center = offsets[i] + scales[i] * cs[i];
      pose.translation = -(pose.rotation * center);
    }

    // Stats after the pose step (same observations; points as optimised,
    // which is also what the intrinsics step sees).
    sum_err = 0;
    for (size_t p = 0; p < points.size(); ++p) {
      const RayTrack& track = tracks[points[p].track_idx];
      points[p].xyz = xyz[p];
      for (size_t k = 0; k < track.size(); ++k) {
        const double e = RayAngularError(
            track[k].ray, new_poses[track[k].image_idx].Matrix(), xyz[p]);
        points[p].errors_rad[k] = e;
        sum_err += e;
        stats.cost_after += 0.5 * Rho(options, e * e);
      }
    }
    stats.mean_error_after_rad = sum_err / n_obs;
    for (int i = 0; i < num_images; ++i) {
      const double dr = poses[i].rotation.angularDistance(new_poses[i].rotation);
      const double dc =
          (poses[i].Center() - new_poses[i].Center()).norm() / scene_scale;
      stats.max_pose_change = std::max({stats.max_pose_change, dr, dc});
    }
    poses = new_poses;
    result.poses = poses;
    result.iterations.push_back(stats);
    if (options.verbose) {
      std::fprintf(stderr,
                   "camera-only BA iteration %d: %d reliable points, %d obs, "
                   "mean error %.6g -> %.6g rad, cost %.6g -> %.6g, max pose "
                   "change %.3g\n",
                   iter, stats.num_reliable_points,
                   stats.num_reliable_observations, stats.mean_error_before_rad,
                   stats.mean_error_after_rad, stats.cost_before,
                   stats.cost_after, stats.max_pose_change);
    }

    if (options.intrinsics_step) {
      if (!options.intrinsics_step(&poses, points, &tracks)) {
        return finish(CameraOnlyBAStatus::kSolverFailure,
                      "the intrinsics step failed");
      }
      result.poses = poses;
      for (auto& track : tracks) {
        for (auto& obs : track) {
          if (!obs.ray.allFinite() || !(obs.ray.norm() > 0)) {
            return finish(CameraOnlyBAStatus::kSolverFailure,
                          "the intrinsics step produced an invalid ray");
          }
          obs.ray.normalize();
        }
      }
    }

    const bool cost_converged =
        std::abs(stats.cost_before - stats.cost_after) <=
        options.function_tolerance * stats.cost_before;
    const bool params_converged =
        stats.max_pose_change <= options.parameter_tolerance;
    if (cost_converged || params_converged) break;
  }

  // ---- Final re-triangulation from the refined poses -------------------
  if (!EvaluateTau(options, num_images, &tau, &tau_message, &tau_image)) {
    return finish(CameraOnlyBAStatus::kInvalidInput, tau_message, tau_image);
  }
  result.points =
      TriangulateReliablePoints(poses, tracks, tau, options.refine_points,
                                options.max_num_point_iterations,
                                &result.num_triangulated_tracks);
  if (result.points.empty()) {
    return finish(CameraOnlyBAStatus::kNoReliablePoints,
                  "no reliable point remains at the refined poses; increase "
                  "tau");
  }
  double sum_err = 0;
  int n_obs = 0;
  for (const auto& p : result.points) {
    for (const double e : p.errors_rad) {
      sum_err += e;
      ++n_obs;
    }
  }
  result.final_mean_error_rad = sum_err / n_obs;
  return finish(CameraOnlyBAStatus::kSuccess, "");
}

}  // namespace sphera
