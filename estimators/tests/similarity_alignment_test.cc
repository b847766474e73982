#include "estimators/similarity_alignment.h"

#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace sphera {
namespace {

double AngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180 / M_PI;
}

Eigen::Matrix3d RandomRotation(std::mt19937* rng, double max_angle) {
  std::uniform_real_distribution<double> uniform(-1, 1);
  const Eigen::Vector3d axis =
      Eigen::Vector3d(uniform(*rng), uniform(*rng), uniform(*rng)).normalized();
  return Eigen::AngleAxisd(max_angle * uniform(*rng), axis).toRotationMatrix();
}

TEST(GeodesicMedianRotation, MajorityIsReturnedExactly) {
  std::mt19937 rng(3);
  const Eigen::Matrix3d truth = RandomRotation(&rng, 3.0);
  std::vector<Eigen::Matrix3d> rotations(7, truth);
  rotations.push_back(truth * RandomRotation(&rng, 0.2));
  rotations.push_back(truth * RandomRotation(&rng, 0.5));
  EXPECT_LT(AngleDeg(GeodesicMedianRotation(rotations), truth), 1e-9);
}

TEST(GeodesicMedianRotation, SymmetricNoiseAveragesOut) {
  std::mt19937 rng(5);
  const Eigen::Matrix3d truth = RandomRotation(&rng, 3.0);
  std::vector<Eigen::Matrix3d> rotations;
  for (int i = 0; i < 200; ++i) {
    rotations.push_back(truth * RandomRotation(&rng, 0.01));
  }
  const Eigen::Matrix3d median = GeodesicMedianRotation(rotations);
  EXPECT_LT(AngleDeg(median, truth), 0.1);
  // The median beats the first sample, which is off by up to 0.57 degrees.
  double sum_median = 0;
  double sum_first = 0;
  for (const Eigen::Matrix3d& rotation : rotations) {
    sum_median += AngleDeg(median, rotation);
    sum_first += AngleDeg(rotations[0], rotation);
  }
  EXPECT_LE(sum_median, sum_first);
}

TEST(AlignCentersWithRotation, RecoversScaleAndTranslation) {
  std::mt19937 rng(7);
  const Eigen::Matrix3d R = RandomRotation(&rng, 3.0);
  const double scale = 2.5;
  const Eigen::Vector3d translation(1, -2, 3);
  std::vector<Eigen::Vector3d> src;
  std::vector<Eigen::Vector3d> tgt;
  std::uniform_real_distribution<double> uniform(-2, 2);
  for (int i = 0; i < 9; ++i) {
    src.emplace_back(uniform(rng), uniform(rng), uniform(rng));
    tgt.push_back(scale * R * src.back() + translation);
  }
  double estimated_scale = 0;
  Eigen::Vector3d estimated_translation;
  ASSERT_TRUE(AlignCentersWithRotation(
      src, tgt, R, &estimated_scale, &estimated_translation));
  EXPECT_NEAR(estimated_scale, scale, 1e-12);
  EXPECT_LT((estimated_translation - translation).norm(), 1e-12);
}

TEST(AlignCentersWithRotation, RejectsDegenerateInput) {
  double scale = 0;
  Eigen::Vector3d translation;
  const std::vector<Eigen::Vector3d> same(3, Eigen::Vector3d(1, 2, 3));
  EXPECT_FALSE(AlignCentersWithRotation(same, same, Eigen::Matrix3d::Identity(),
                                        &scale, &translation));
  EXPECT_FALSE(AlignCentersWithRotation({Eigen::Vector3d::Zero()},
                                        {Eigen::Vector3d::Zero()},
                                        Eigen::Matrix3d::Identity(), &scale,
                                        &translation));
}

}  // namespace
}  // namespace sphera
