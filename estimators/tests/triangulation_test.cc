#include "estimators/triangulation.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimators/tests/test_utils.h"

namespace sphera {
namespace {

std::vector<Eigen::Matrix3x4d> RandomCameras(std::mt19937* rng, int n) {
  std::vector<Eigen::Matrix3x4d> cams;
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d R = test::RandomRotation(rng);
    const Eigen::Vector3d center = 2.0 * test::RandomUnitVector(rng);
    cams.push_back(test::MakePose(R, -R * center));
  }
  return cams;
}

std::vector<Eigen::Vector3d> RaysOf(const std::vector<Eigen::Matrix3x4d>& cams,
                                    const Eigen::Vector3d& X) {
  std::vector<Eigen::Vector3d> rays;
  for (const auto& P : cams) {
    rays.push_back((P.leftCols<3>() * X + P.col(3)).normalized());
  }
  return rays;
}

TEST(Triangulation, PointBehindImagePlane) {
  std::mt19937 rng(30);
  int num_behind_cases = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const auto cams = RandomCameras(&rng, 2 + trial % 4);
    const Eigen::Vector3d X = 8.0 * test::RandomUnitVector(&rng);
    const auto rays = RaysOf(cams, X);
    for (const auto& r : rays) num_behind_cases += r.z() < 0;
    const auto Xt = TriangulateRays(cams, rays);
    ASSERT_TRUE(Xt.has_value());
    EXPECT_LT((*Xt - X).norm(), 1e-9 * X.norm());
    EXPECT_TRUE(CheckRayCheirality(cams, rays, *Xt));
    for (size_t i = 0; i < cams.size(); ++i) {
      EXPECT_LT(RayAngularError(rays[i], cams[i], *Xt), 1e-9);
    }
  }
  EXPECT_GT(num_behind_cases, 50);
}

TEST(Triangulation, ExplicitlyBehindBothCameras) {
  // Two cameras looking along +z, point at z = -5 (behind both image planes).
  const Eigen::Matrix3x4d P1 =
      test::MakePose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 0));
  const Eigen::Matrix3x4d P2 =
      test::MakePose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-1, 0, 0));
  const Eigen::Vector3d X(0.3, -0.2, -5);
  const std::vector<Eigen::Matrix3x4d> cams = {P1, P2};
  const auto rays = RaysOf(cams, X);
  ASSERT_LT(rays[0].z(), 0);
  ASSERT_LT(rays[1].z(), 0);
  const auto Xt = TriangulateRays(cams, rays);
  ASSERT_TRUE(Xt.has_value());
  EXPECT_LT((*Xt - X).norm(), 1e-12);
  EXPECT_TRUE(CheckRayCheirality(cams, rays, *Xt));
}

TEST(Triangulation, CheiralityRejectsPointsBehindRays) {
  std::mt19937 rng(31);
  for (int trial = 0; trial < 50; ++trial) {
    const auto cams = RandomCameras(&rng, 3);
    const Eigen::Vector3d X = 8.0 * test::RandomUnitVector(&rng);
    auto rays = RaysOf(cams, X);
    rays[trial % 3] = -rays[trial % 3];  // antipodal ray: point is behind it
    // The linear constraints are sign-blind, so the point is still found...
    const auto Xt = TriangulateRays(cams, rays);
    ASSERT_TRUE(Xt.has_value());
    EXPECT_LT((*Xt - X).norm(), 1e-8 * X.norm());
    // ...but cheirality rejects it, and its angular error is ~180 deg.
    EXPECT_FALSE(CheckRayCheirality(cams, rays, *Xt));
    EXPECT_FALSE(HasPositiveRayDepth(rays[trial % 3], cams[trial % 3], *Xt));
    EXPECT_GT(RayAngularError(rays[trial % 3], cams[trial % 3], *Xt),
              M_PI - 1e-6);
  }
}

TEST(Triangulation, DegenerateCases) {
  const Eigen::Matrix3x4d P1 =
      test::MakePose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 0));
  const Eigen::Matrix3x4d P2 =
      test::MakePose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-1, 0, 0));
  const Eigen::Vector3d r(0, 0.6, -0.8);
  // Parallel rays: point at infinity.
  EXPECT_FALSE(TriangulateRays({P1, P2}, {r, r}).has_value());
  // One observation.
  EXPECT_FALSE(TriangulateRays({P1}, {r}).has_value());
  // Same centre.
  EXPECT_FALSE(TriangulateRays({P1, P1}, {r, Eigen::Vector3d(1, 0, 0)})
                   .has_value());
}

TEST(Triangulation, RefinementReducesAngularError) {
  std::mt19937 rng(32);
  const double sigma = 2e-3;
  int improved = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const auto cams = RandomCameras(&rng, 4);
    const Eigen::Vector3d X = 6.0 * test::RandomUnitVector(&rng);
    auto rays = RaysOf(cams, X);
    for (auto& r : rays) r = test::NoisyRay(r, sigma, &rng);
    const auto X0 = TriangulateRays(cams, rays);
    ASSERT_TRUE(X0.has_value());
    auto cost = [&](const Eigen::Vector3d& P) {
      double c = 0;
      for (size_t i = 0; i < cams.size(); ++i) {
        c += std::pow(RayAngularError(rays[i], cams[i], P), 2);
      }
      return c;
    };
    Eigen::Vector3d X1 = *X0;
    ASSERT_TRUE(RefineTriangulatedPoint(cams, rays, &X1));
    EXPECT_LE(cost(X1), cost(*X0) * (1 + 1e-12));
    improved += cost(X1) < cost(*X0);
    EXPECT_LT((X1 - X).norm(), 0.2);
    // Gradient of the refined cost vanishes: a small step does not improve.
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d(k) = 1e-5;
      EXPECT_GE(cost(X1 + d), cost(X1) * (1 - 1e-9));
      EXPECT_GE(cost(X1 - d), cost(X1) * (1 - 1e-9));
    }
  }
  EXPECT_GT(improved, 20);
}

}  // namespace
}  // namespace sphera
