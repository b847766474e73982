#include "estimators/absolute_pose.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimators/tests/test_utils.h"

namespace sphera {
namespace {

struct AbsScene {
  Eigen::Matrix3x4d cam_from_world;
  std::vector<Eigen::Vector3d> rays, points;
  std::vector<char> is_outlier;
};

// World points all around the camera (full sphere of directions).
AbsScene MakeScene(std::mt19937* rng, int n, double sigma,
                   double outlier_ratio) {
  AbsScene s;
  const Eigen::Matrix3d R = test::RandomRotation(rng);
  const Eigen::Vector3d center = 5.0 * test::RandomUnitVector(rng);
  s.cam_from_world = test::MakePose(R, -R * center);
  std::uniform_real_distribution<double> depth(1, 20);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d dir_cam = test::RandomUnitVector(rng);
    const Eigen::Vector3d X_cam = depth(*rng) * dir_cam;
    s.points.push_back(R.transpose() * X_cam + center);
    s.rays.push_back(test::NoisyRay(dir_cam, sigma, rng));
    s.is_outlier.push_back(0);
  }
  const int num_outliers = static_cast<int>(std::round(outlier_ratio * n));
  for (int i = 0; i < num_outliers; ++i) {
    s.rays[i] = test::RandomUnitVector(rng);
    s.is_outlier[i] = 1;
  }
  return s;
}

double PoseError(const Eigen::Matrix3x4d& a, const Eigen::Matrix3x4d& b) {
  return (a - b).norm();
}

TEST(AbsolutePose, P3PAllAroundIncludingBehindNoiseFree) {
  std::mt19937 rng(20);
  const int kTrials = 200;
  int num_exact = 0, num_behind_trials = 0;
  double worst = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const AbsScene s = MakeScene(&rng, 3, 0, 0);
    bool any_behind = false;
    for (const auto& r : s.rays) any_behind |= r.z() < 0;
    num_behind_trials += any_behind;
    std::vector<Eigen::Matrix3x4d> models;
    P3PRayEstimator::Estimate(s.rays, s.points, &models);
    double best = 1e9;
    for (const auto& m : models) best = std::min(best, PoseError(m, s.cam_from_world));
    worst = std::max(worst, best);
    if (best < 1e-9) ++num_exact;
  }
  EXPECT_GT(num_behind_trials, kTrials / 2);
  // P3P is ill-conditioned for rare near-degenerate triplets; RANSAC copes.
  EXPECT_GE(num_exact, kTrials * 97 / 100) << "worst " << worst;
}

TEST(AbsolutePose, P3PAllPointsBehindImagePlane) {
  std::mt19937 rng(21);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Matrix3d R = test::RandomRotation(&rng);
    const Eigen::Vector3d t = test::RandomUnitVector(&rng);
    const Eigen::Matrix3x4d P = test::MakePose(R, t);
    std::vector<Eigen::Vector3d> rays, points;
    std::uniform_real_distribution<double> depth(1, 10);
    while (rays.size() < 3) {
      Eigen::Vector3d d = test::RandomUnitVector(&rng);
      if (d.z() > -0.2) continue;  // strictly behind z = 0
      rays.push_back(d);
      points.push_back(R.transpose() * (depth(rng) * d - t));
    }
    std::vector<Eigen::Matrix3x4d> models;
    P3PRayEstimator::Estimate(rays, points, &models);
    double best = 1e9;
    for (const auto& m : models) best = std::min(best, PoseError(m, P));
    EXPECT_LT(best, 1e-9);
  }
}

TEST(AbsolutePose, ResidualIsSquaredAngleAndBehindIsOutlier) {
  const Eigen::Matrix3x4d P = test::MakePose(Eigen::Matrix3d::Identity(),
                                             Eigen::Vector3d::Zero());
  const Eigen::Vector3d ray(0, 0, 1);
  std::vector<double> res;
  P3PRayEstimator::Residuals({ray, ray, ray},
                             {Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(0, 1, 1),
                              Eigen::Vector3d(0, 0, -5)},
                             P, &res);
  EXPECT_NEAR(res[0], 0, 1e-30);
  EXPECT_NEAR(res[1], std::pow(M_PI / 4, 2), 1e-14);
  EXPECT_NEAR(res[2], M_PI * M_PI, 1e-12);
}

TEST(AbsolutePose, NonMinimalUPnPAllAroundNoiseFree) {
  std::mt19937 rng(22);
  for (int trial = 0; trial < 20; ++trial) {
    const AbsScene s = MakeScene(&rng, 50, 0, 0);
    std::vector<Eigen::Matrix3x4d> models;
    P3PRayEstimator::Estimate(s.rays, s.points, &models);
    ASSERT_EQ(models.size(), 1u);
    EXPECT_LT(PoseError(models[0], s.cam_from_world), 1e-9);
  }
}

TEST(AbsolutePose, RansacWithNoiseAndOutliers) {
  std::mt19937 rng(23);
  const double sigma = 1e-3;
  for (int trial = 0; trial < 5; ++trial) {
    const AbsScene s = MakeScene(&rng, 300, sigma, 0.05);
    const double max_residual = std::pow(3 * sigma, 2);
    std::uniform_int_distribution<size_t> pick(0, s.rays.size() - 1);
    size_t best_count = 0;
    Eigen::Matrix3x4d best;
    std::vector<double> res;
    for (int it = 0; it < 100; ++it) {
      std::vector<size_t> idx;
      while (idx.size() < 3) {
        const size_t k = pick(rng);
        if (std::find(idx.begin(), idx.end(), k) == idx.end()) idx.push_back(k);
      }
      std::vector<Eigen::Vector3d> r, X;
      for (size_t k : idx) {
        r.push_back(s.rays[k]);
        X.push_back(s.points[k]);
      }
      std::vector<Eigen::Matrix3x4d> models;
      P3PRayEstimator::Estimate(r, X, &models);
      for (const auto& m : models) {
        P3PRayEstimator::Residuals(s.rays, s.points, m, &res);
        const size_t c = std::count_if(res.begin(), res.end(), [&](double x) {
          return x <= max_residual;
        });
        if (c > best_count) {
          best_count = c;
          best = m;
        }
      }
    }
    P3PRayEstimator::Residuals(s.rays, s.points, best, &res);
    std::vector<char> mask(res.size());
    size_t outliers_in = 0;
    for (size_t i = 0; i < res.size(); ++i) {
      mask[i] = res[i] <= max_residual;
      outliers_in += mask[i] && s.is_outlier[i];
    }
    EXPECT_LE(outliers_in, 1u);
    AbsolutePoseRefineOptions options;
    options.loss_scale_rad = 3 * sigma;
    ASSERT_TRUE(RefineAbsolutePose(s.rays, s.points, mask, &best, options));
    const Eigen::Matrix3d R = best.leftCols<3>();
    const Eigen::Matrix3d R_true = s.cam_from_world.leftCols<3>();
    EXPECT_LT(test::RotationErrorRad(R, R_true), 0.5 * sigma);
    const Eigen::Vector3d c = -R.transpose() * best.col(3);
    const Eigen::Vector3d c_true =
        -R_true.transpose() * s.cam_from_world.col(3);
    EXPECT_LT((c - c_true).norm(), 0.02);
  }
}

TEST(AbsolutePose, RefineFromPerturbedNoiseFree) {
  std::mt19937 rng(24);
  const AbsScene s = MakeScene(&rng, 40, 0, 0);
  Eigen::Matrix3x4d P = s.cam_from_world;
  P.leftCols<3>() = P.leftCols<3>() *
                    Eigen::AngleAxisd(0.05, test::RandomUnitVector(&rng)).matrix();
  P.col(3) += 0.1 * test::RandomUnitVector(&rng);
  ASSERT_TRUE(RefineAbsolutePose(s.rays, s.points, {}, &P));
  EXPECT_LT(PoseError(P, s.cam_from_world), 1e-9);
}

}  // namespace
}  // namespace sphera
