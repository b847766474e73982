#include "estimators/rotation_from_rays.h"

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "estimators/tests/test_utils.h"

namespace sphera {
namespace {

double AngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180 / M_PI;
}

TEST(RotationFromRays, ExactRotationIsRecovered) {
  std::mt19937 rng(1);
  const Eigen::Matrix3d cam2_from_cam1 = test::RandomRotation(&rng);
  std::vector<Eigen::Vector3d> rays1, rays2;
  for (int i = 0; i < 50; ++i) {
    rays1.push_back(test::RandomUnitVector(&rng));
    rays2.push_back(cam2_from_cam1 * rays1.back());
  }
  const RotationFromRays result =
      EstimateRotationFromRays(rays1, rays2, RotationFromRaysOptions());
  ASSERT_TRUE(result.success);
  EXPECT_EQ(result.num_inliers, 50);
  EXPECT_LT(AngleDeg(result.cam2_from_cam1, cam2_from_cam1), 1e-9);
}

TEST(RotationFromRays, OutliersAreTolerated) {
  std::mt19937 rng(2);
  const Eigen::Matrix3d cam2_from_cam1 = test::RandomRotation(&rng);
  std::vector<Eigen::Vector3d> rays1, rays2;
  std::vector<bool> is_outlier;
  for (int i = 0; i < 200; ++i) {
    rays1.push_back(test::RandomUnitVector(&rng));
    // 40% wrong matches: rays anywhere.
    const bool outlier = i % 5 < 2;
    rays2.push_back(outlier ? test::RandomUnitVector(&rng)
                            : test::NoisyRay(cam2_from_cam1 * rays1.back(),
                                             0.002, &rng));
    is_outlier.push_back(outlier);
  }
  const RotationFromRays result =
      EstimateRotationFromRays(rays1, rays2, RotationFromRaysOptions());
  ASSERT_TRUE(result.success);
  EXPECT_LT(AngleDeg(result.cam2_from_cam1, cam2_from_cam1), 0.1);
  int wrong_labels = 0;
  for (size_t i = 0; i < rays1.size(); ++i) {
    // An outlier may by chance fall within the threshold; count the rest.
    if (!is_outlier[i] && !result.inlier_mask[i]) ++wrong_labels;
  }
  EXPECT_EQ(wrong_labels, 0);
  EXPECT_GE(result.num_inliers, 120);
  EXPECT_LT(result.num_inliers, 130);
}

// Two lenses 6 cm apart, points 2 m away: the parallax (up to 1.7°) stays
// inside the default threshold, and the fitted rotation is the true one to
// a fraction of the parallax.
TEST(RotationFromRays, ParallaxOfASixCentimetreBaselineAtTwoMetres) {
  std::mt19937 rng(3);
  const Eigen::Matrix3d cam2_from_cam1 =
      Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d center2_in_cam1(0.06, 0, 0);
  std::vector<Eigen::Vector3d> rays1, rays2;
  double max_parallax_rad = 0;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d point_in_cam1 = 2.0 * test::RandomUnitVector(&rng);
    rays1.push_back(point_in_cam1.normalized());
    rays2.push_back(
        (cam2_from_cam1 * (point_in_cam1 - center2_in_cam1)).normalized());
    max_parallax_rad = std::max(
        max_parallax_rad,
        std::acos(std::min(1.0, rays2.back().dot(cam2_from_cam1 *
                                                  rays1.back()))));
  }
  EXPECT_GT(max_parallax_rad * 180 / M_PI, 1.5);  // the case is not trivial
  const RotationFromRaysOptions options;
  EXPECT_LT(max_parallax_rad, options.max_error_rad);
  const RotationFromRays result =
      EstimateRotationFromRays(rays1, rays2, options);
  ASSERT_TRUE(result.success);
  EXPECT_EQ(result.num_inliers, 300);
  EXPECT_LT(AngleDeg(result.cam2_from_cam1, cam2_from_cam1), 1.0);
}

TEST(RotationFromRays, TooFewRaysAreNoEstimate) {
  std::vector<Eigen::Vector3d> rays = {Eigen::Vector3d::UnitX(),
                                       Eigen::Vector3d::UnitY()};
  EXPECT_FALSE(
      EstimateRotationFromRays(rays, rays, RotationFromRaysOptions()).success);
}

TEST(RotationFromRays, BadInputIsRefused) {
  std::vector<Eigen::Vector3d> rays1(10, Eigen::Vector3d::UnitZ());
  std::vector<Eigen::Vector3d> rays2(9, Eigen::Vector3d::UnitZ());
  EXPECT_THROW(
      EstimateRotationFromRays(rays1, rays2, RotationFromRaysOptions()),
      std::invalid_argument);
  RotationFromRaysOptions options;
  options.max_error_rad = 0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace sphera
