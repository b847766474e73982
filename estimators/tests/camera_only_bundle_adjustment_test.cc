#include "estimators/camera_only_bundle_adjustment.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "estimators/tests/test_utils.h"
#include "estimators/triangulation.h"

namespace sphera {
namespace {

constexpr double kRadPerPx = 2 * M_PI / 2048;  // equirectangular 2048 x 1024

// The paper's room: 4 x 4 x 3 m (x, z horizontal, y vertical), 9 spherical
// cameras on a 3 x 3 grid at 1.5 m height with random orientations, points
// uniformly on the 6 walls; every camera sees every point (convex room), so
// about half of the rays of each camera have z < 0.
struct Scene {
  std::vector<CameraPose> poses;
  std::vector<Eigen::Vector3d> points;
  std::vector<RayTrack> tracks;
};

Scene MakeRoom(int num_points, std::mt19937* rng) {
  Scene scene;
  for (int gz = -1; gz <= 1; ++gz) {
    for (int gx = -1; gx <= 1; ++gx) {
      CameraPose pose;
      pose.rotation = Eigen::Quaterniond(test::RandomRotation(rng));
      const Eigen::Vector3d center(gx * 1.0, 0.0, gz * 1.0);
      pose.translation = -(pose.rotation * center);
      scene.poses.push_back(pose);
    }
  }
  std::uniform_real_distribution<double> ux(-2, 2), uy(-1.5, 1.5);
  std::uniform_int_distribution<int> wall(0, 5);
  for (int j = 0; j < num_points; ++j) {
    Eigen::Vector3d X(ux(*rng), uy(*rng), ux(*rng));
    switch (wall(*rng)) {
      case 0: X.x() = -2; break;
      case 1: X.x() = 2; break;
      case 2: X.y() = -1.5; break;
      case 3: X.y() = 1.5; break;
      case 4: X.z() = -2; break;
      default: X.z() = 2; break;
    }
    scene.points.push_back(X);
    RayTrack track;
    for (int i = 0; i < static_cast<int>(scene.poses.size()); ++i) {
      RayObservation obs;
      obs.image_idx = i;
      obs.ray = (scene.poses[i].rotation * X + scene.poses[i].translation)
                    .normalized();
      track.push_back(obs);
    }
    scene.tracks.push_back(track);
  }
  return scene;
}

std::vector<CameraPose> PerturbPoses(const std::vector<CameraPose>& poses,
                                     double angle_rad, double dist_m,
                                     std::mt19937* rng) {
  std::vector<CameraPose> out = poses;
  for (auto& pose : out) {
    const Eigen::Vector3d C = pose.Center();
    pose.rotation =
        Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad,
                                             test::RandomUnitVector(rng))) *
        pose.rotation;
    const Eigen::Vector3d C2 = C + dist_m * test::RandomUnitVector(rng);
    pose.translation = -(pose.rotation * C2);
  }
  return out;
}

// Errors after removing the gauge: similarity (Umeyama on the centres) from
// the estimate to the ground truth. Max rotation [deg] and position [m].
void PoseErrors(const std::vector<CameraPose>& gt,
                const std::vector<CameraPose>& est, double* max_rot_deg,
                double* max_pos_m) {
  Eigen::Matrix3Xd src(3, gt.size()), dst(3, gt.size());
  for (size_t i = 0; i < gt.size(); ++i) {
    src.col(i) = est[i].Center();
    dst.col(i) = gt[i].Center();
  }
  const Eigen::Matrix4d S = Eigen::umeyama(src, dst, true);
  const double s = S.block<3, 3>(0, 0).determinant() > 0
                       ? std::cbrt(S.block<3, 3>(0, 0).determinant())
                       : 1;
  const Eigen::Matrix3d R = S.block<3, 3>(0, 0) / s;
  *max_rot_deg = 0;
  *max_pos_m = 0;
  for (size_t i = 0; i < gt.size(); ++i) {
    const Eigen::Vector3d C = S.block<3, 3>(0, 0) * est[i].Center() +
                              S.block<3, 1>(0, 3);
    *max_pos_m = std::max(*max_pos_m, (C - gt[i].Center()).norm());
    const Eigen::Matrix3d R_est_aligned =
        est[i].rotation.toRotationMatrix() * R.transpose();
    *max_rot_deg = std::max(
        *max_rot_deg,
        test::RotationErrorRad(gt[i].rotation.toRotationMatrix(),
                               R_est_aligned) *
            180 / M_PI);
  }
}

TEST(CameraOnlyBundleAdjustment, NoiseFreeRecoversPoses) {
  std::mt19937 rng(42);
  const Scene scene = MakeRoom(200, &rng);
  int num_behind = 0, num_rays = 0;
  for (const auto& track : scene.tracks) {
    for (const auto& obs : track) {
      num_behind += obs.ray.z() < 0;
      ++num_rays;
    }
  }
  EXPECT_GT(num_behind, num_rays / 4);

  CameraOnlyBAProblem problem;
  problem.poses = PerturbPoses(scene.poses, 0.5 * M_PI / 180, 0.02, &rng);
  problem.tracks = scene.tracks;
  double rot0, pos0;
  PoseErrors(scene.poses, problem.poses, &rot0, &pos0);
  EXPECT_GT(rot0, 0.1);

  CameraOnlyBAOptions options;
  options.tau_rad = {0.1};  // generous: the initial errors are ~1 deg
  options.max_iterations = 300;
  options.function_tolerance = 0;
  options.parameter_tolerance = 1e-13;
  const CameraOnlyBAResult result =
      CameraOnlyBundleAdjustment(problem, options);
  ASSERT_TRUE(result.Success()) << result.message;
  EXPECT_EQ(result.points.size(), scene.points.size());
  double rot, pos;
  PoseErrors(scene.poses, result.poses, &rot, &pos);
  EXPECT_LT(rot, 1e-6) << "iterations " << result.iterations.size();
  EXPECT_LT(pos, 1e-7) << "iterations " << result.iterations.size();
  EXPECT_LT(result.final_mean_error_rad, 1e-9);
  // The gauge: camera 0 untouched, baseline |C1 - C0| kept.
  EXPECT_TRUE(result.poses[0].rotation.isApprox(problem.poses[0].rotation, 1e-14));
  EXPECT_TRUE(result.poses[0].translation.isApprox(problem.poses[0].translation, 1e-14));
  EXPECT_NEAR((result.poses[1].Center() - result.poses[0].Center()).norm(),
              (problem.poses[1].Center() - problem.poses[0].Center()).norm(),
              1e-12);
  // The mean error decreases over the iterations.
  ASSERT_GE(result.iterations.size(), 2u);
  EXPECT_LT(result.iterations.back().mean_error_before_rad,
            result.iterations.front().mean_error_before_rad);
  for (const auto& it : result.iterations) {
    EXPECT_LE(it.cost_after, it.cost_before * (1 + 1e-12) + 1e-300);
  }
}

TEST(CameraOnlyBundleAdjustment, TauExcludesOutliers) {
  std::mt19937 rng(7);
  Scene scene = MakeRoom(300, &rng);
  const double sigma = 0.5 * kRadPerPx;
  std::set<int> outlier_tracks;
  std::uniform_int_distribution<int> pick(0, 8);
  for (size_t j = 0; j < scene.tracks.size(); ++j) {
    for (auto& obs : scene.tracks[j]) {
      obs.ray = test::NoisyRay(obs.ray, sigma, &rng);
    }
    if (j % 10 == 3) {  // 10% of the tracks get one gross outlier (10 deg)
      auto& obs = scene.tracks[j][pick(rng)];
      obs.ray = test::PerturbRay(obs.ray, 10 * M_PI / 180, &rng);
      outlier_tracks.insert(static_cast<int>(j));
    }
  }
  CameraOnlyBAProblem problem;
  problem.poses = PerturbPoses(scene.poses, 0.5 * M_PI / 180, 0.02, &rng);
  problem.tracks = scene.tracks;

  // Stage 1: the perturbation makes the errors ~1 deg, so start with a loose
  // tau (as a user would), then tau = 3 px from the refined poses.
  CameraOnlyBAOptions options;
  options.tau_rad = {0.05};
  options.max_iterations = 5;
  CameraOnlyBAResult result = CameraOnlyBundleAdjustment(problem, options);
  ASSERT_TRUE(result.Success()) << result.message;
  options.tau_rad = {3 * kRadPerPx};
  options.max_iterations = 50;
  problem.poses = result.poses;
  result = CameraOnlyBundleAdjustment(problem, options);
  ASSERT_TRUE(result.Success()) << result.message;
  int num_outliers_kept = 0;
  for (const auto& p : result.points) {
    num_outliers_kept += outlier_tracks.count(p.track_idx);
    ASSERT_FALSE(p.errors_rad.empty());
    EXPECT_LE(*std::max_element(p.errors_rad.begin(), p.errors_rad.end()),
              3 * kRadPerPx);
  }
  EXPECT_EQ(num_outliers_kept, 0);
  EXPECT_GT(result.points.size(), 0.8 * (scene.tracks.size() -
                                         outlier_tracks.size()));
  double rot, pos;
  PoseErrors(scene.poses, result.poses, &rot, &pos);
  // From 0.5 deg / 2 cm to the noise level (sigma = 0.09 deg per ray).
  EXPECT_LT(rot, 0.05);
  EXPECT_LT(pos, 3e-3);
  EXPECT_LT(result.final_mean_error_rad, 2 * sigma);
}

TEST(CameraOnlyBundleAdjustment, TauBelowNoiseFloorFails) {
  std::mt19937 rng(3);
  Scene scene = MakeRoom(100, &rng);
  for (auto& track : scene.tracks) {
    for (auto& obs : track) obs.ray = test::NoisyRay(obs.ray, 1e-3, &rng);
  }
  CameraOnlyBAProblem problem;
  problem.poses = scene.poses;
  problem.tracks = scene.tracks;
  CameraOnlyBAOptions options;
  options.tau_rad = {1e-7};
  const CameraOnlyBAResult result =
      CameraOnlyBundleAdjustment(problem, options);
  EXPECT_EQ(result.status, CameraOnlyBAStatus::kNoReliablePoints);
  EXPECT_NE(result.message.find("noise floor"), std::string::npos)
      << result.message;
  // Poses are returned unchanged on failure.
  for (size_t i = 0; i < scene.poses.size(); ++i) {
    EXPECT_TRUE(result.poses[i].translation.isApprox(problem.poses[i].translation));
  }
}

TEST(CameraOnlyBundleAdjustment, ReliableSetIsExactlyTracksWithinTau) {
  std::mt19937 rng(11);
  Scene scene = MakeRoom(300, &rng);
  for (auto& track : scene.tracks) {
    for (auto& obs : track) obs.ray = test::NoisyRay(obs.ray, 2e-3, &rng);
  }
  CameraOnlyBAProblem problem;
  problem.poses = scene.poses;
  problem.tracks = scene.tracks;
  CameraOnlyBAOptions options;
  options.tau_rad = {4e-3};  // about the median max error: both sets large
  options.max_iterations = 5;
  const CameraOnlyBAResult result =
      CameraOnlyBundleAdjustment(problem, options);
  ASSERT_TRUE(result.Success()) << result.message;

  // Independent computation at the returned poses.
  std::set<int> expected;
  for (size_t j = 0; j < scene.tracks.size(); ++j) {
    std::vector<Eigen::Matrix3x4d> cams;
    std::vector<Eigen::Vector3d> rays;
    for (const auto& obs : scene.tracks[j]) {
      cams.push_back(result.poses[obs.image_idx].Matrix());
      rays.push_back(obs.ray);
    }
    auto X = TriangulateRays(cams, rays);
    ASSERT_TRUE(X.has_value());
    ASSERT_TRUE(RefineTriangulatedPoint(cams, rays, &*X,
                                        options.max_num_point_iterations));
    bool within = CheckRayCheirality(cams, rays, *X);
    for (size_t k = 0; k < rays.size(); ++k) {
      within = within && RayAngularError(rays[k], cams[k], *X) <= 4e-3;
    }
    if (within) expected.insert(static_cast<int>(j));
  }
  std::set<int> got;
  for (const auto& p : result.points) got.insert(p.track_idx);
  EXPECT_EQ(got, expected);
  EXPECT_GT(got.size(), 30u);
  EXPECT_LT(got.size(), scene.tracks.size() - 30);
  for (const auto& it : result.iterations) {
    EXPECT_GT(it.num_reliable_points, 0);
    EXPECT_EQ(it.num_reliable_observations, 9 * it.num_reliable_points);
  }
}

TEST(CameraOnlyBundleAdjustment, FailureStatuses) {
  std::mt19937 rng(5);
  const Scene scene = MakeRoom(50, &rng);
  CameraOnlyBAOptions options;
  options.tau_rad = {0.01};

  {  // tau <= 0
    CameraOnlyBAProblem problem{scene.poses, scene.tracks};
    CameraOnlyBAOptions bad = options;
    bad.tau_rad = {0.0};
    const auto r = CameraOnlyBundleAdjustment(problem, bad);
    EXPECT_EQ(r.status, CameraOnlyBAStatus::kInvalidInput);
    EXPECT_NE(r.message.find("tau_rad"), std::string::npos) << r.message;
  }
  {  // Too few observations in image 4.
    CameraOnlyBAProblem problem{scene.poses, scene.tracks};
    for (size_t j = 3; j < problem.tracks.size(); ++j) {
      auto& t = problem.tracks[j];
      t.erase(std::remove_if(t.begin(), t.end(),
                             [](const RayObservation& o) {
                               return o.image_idx == 4;
                             }),
              t.end());
    }
    const auto r = CameraOnlyBundleAdjustment(problem, options);
    EXPECT_EQ(r.status, CameraOnlyBAStatus::kTooFewObservations);
    EXPECT_EQ(r.image_idx, 4) << r.message;
    EXPECT_NE(r.message.find("observes only"), std::string::npos)
        << r.message;
  }
  {  // Gauge cameras at the same centre.
    CameraOnlyBAProblem problem{scene.poses, scene.tracks};
    problem.poses[1].translation =
        -(problem.poses[1].rotation * problem.poses[0].Center());
    const auto r = CameraOnlyBundleAdjustment(problem, options);
    EXPECT_EQ(r.status, CameraOnlyBAStatus::kDegenerateGeometry);
  }
  {  // All centres coincide: nothing can be triangulated.
    CameraOnlyBAProblem problem{scene.poses, scene.tracks};
    for (auto& p : problem.poses) p.translation.setZero();
    const auto r = CameraOnlyBundleAdjustment(problem, options);
    EXPECT_EQ(r.status, CameraOnlyBAStatus::kDegenerateGeometry) << r.message;
  }
  {  // Unknown image index.
    CameraOnlyBAProblem problem{scene.poses, scene.tracks};
    problem.tracks[0][0].image_idx = 99;
    const auto r = CameraOnlyBundleAdjustment(problem, options);
    EXPECT_EQ(r.status, CameraOnlyBAStatus::kInvalidInput);
  }
}

TEST(CameraOnlyBundleAdjustment, IntrinsicsStepAndCauchy) {
  std::mt19937 rng(9);
  const Scene scene = MakeRoom(100, &rng);
  CameraOnlyBAProblem problem;
  problem.poses = PerturbPoses(scene.poses, 0.2 * M_PI / 180, 0.01, &rng);
  problem.tracks = scene.tracks;
  CameraOnlyBAOptions options;
  options.tau_rad = {0.05};
  options.loss = CameraOnlyBALoss::kCauchy;
  options.loss_scale_rad = 0.01;
  options.max_iterations = 3;
  int calls = 0;
  options.intrinsics_step = [&](std::vector<CameraPose>* poses,
                                const std::vector<ReliablePoint>& points,
                                std::vector<RayTrack>* tracks) {
    ++calls;
    EXPECT_EQ(poses->size(), 9u);
    EXPECT_FALSE(points.empty());
    EXPECT_EQ(tracks->size(), scene.tracks.size());
    return true;
  };
  const auto r = CameraOnlyBundleAdjustment(problem, options);
  ASSERT_TRUE(r.Success()) << r.message;
  EXPECT_EQ(calls, static_cast<int>(r.iterations.size()));
  EXPECT_LT(r.final_mean_error_rad, r.initial_mean_error_rad);

  options.intrinsics_step = [](std::vector<CameraPose>*,
                               const std::vector<ReliablePoint>&,
                               std::vector<RayTrack>*) { return false; };
  EXPECT_EQ(CameraOnlyBundleAdjustment(problem, options).status,
            CameraOnlyBAStatus::kSolverFailure);
}

}  // namespace
}  // namespace sphera
