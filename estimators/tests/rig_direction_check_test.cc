#include "estimators/rig_direction_check.h"

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "estimators/rotation_from_rays.h"
#include "estimators/tests/test_utils.h"

namespace sphera {
namespace {

constexpr double kDeg = M_PI / 180;

// cam_from_rig of lens k of a ring of n lenses looking outwards, 360/n
// degrees apart about the vertical (y).
std::vector<Eigen::Matrix3d> Ring(int num_lenses) {
  std::vector<Eigen::Matrix3d> cam_from_rig;
  for (int k = 0; k < num_lenses; ++k) {
    cam_from_rig.push_back(
        Eigen::AngleAxisd(-2 * M_PI * k / num_lenses, Eigen::Vector3d::UnitY())
            .toRotationMatrix());
  }
  return cam_from_rig;
}

// Neighbouring lenses of the true ring measured in `num_measurements` frames from
// synthetic rays (scene points 2 m away, lenses 6 cm from the rig centre,
// 20% wrong matches), through the robust estimator.
std::vector<LensPairRotation> MeasureNeighbours(
    const std::vector<Eigen::Matrix3d>& true_cam_from_rig, int num_measurements,
    std::mt19937* rng) {
  const int num_lenses = static_cast<int>(true_cam_from_rig.size());
  std::vector<LensPairRotation> measurements;
  for (int frame = 0; frame < num_measurements; ++frame) {
    for (int lens1 = 0; lens1 < num_lenses; ++lens1) {
      const int lens2 = (lens1 + 1) % num_lenses;
      std::vector<Eigen::Vector3d> rays1, rays2;
      for (int i = 0; i < 60; ++i) {
        // Points between the two optical axes, seen by both lenses.
        const Eigen::Vector3d axis =
            (true_cam_from_rig[lens1].row(2) + true_cam_from_rig[lens2].row(2))
                .transpose()
                .normalized();
        const Eigen::Vector3d point_in_rig =
            2.0 * test::PerturbRay(axis, 0.4, rng);
        const Eigen::Vector3d center1 =
            0.06 * true_cam_from_rig[lens1].row(2).transpose();
        const Eigen::Vector3d center2 =
            0.06 * true_cam_from_rig[lens2].row(2).transpose();
        rays1.push_back(
            (true_cam_from_rig[lens1] * (point_in_rig - center1)).normalized());
        rays2.push_back(
            i % 5 == 0
                ? test::RandomUnitVector(rng)
                : (true_cam_from_rig[lens2] * (point_in_rig - center2))
                      .normalized());
      }
      const RotationFromRays rotation =
          EstimateRotationFromRays(rays1, rays2, RotationFromRaysOptions());
      EXPECT_TRUE(rotation.success);
      LensPairRotation measurement;
      measurement.lens1 = lens1;
      measurement.lens2 = lens2;
      measurement.cam2_from_cam1 = rotation.cam2_from_cam1;
      measurement.num_inliers = rotation.num_inliers;
      measurements.push_back(measurement);
    }
  }
  return measurements;
}

TEST(RigDirectionCheck, CorrectConfigNamesNothing) {
  std::mt19937 rng(4);
  const std::vector<Eigen::Matrix3d> ring = Ring(8);
  const std::vector<LensDirection> lenses = CheckRigDirections(
      ring, MeasureNeighbours(ring, 3, &rng), RigDirectionCheckOptions());
  ASSERT_EQ(lenses.size(), 8u);
  for (const LensDirection& lens : lenses) {
    EXPECT_EQ(lens.status, LensDirectionStatus::kConsistent);
    EXPECT_TRUE(lens.measured);
    EXPECT_LT(lens.angle_off_rad, 1.5 * kDeg);
    EXPECT_EQ(lens.num_pairs, 2);
    EXPECT_EQ(lens.num_measurements, 6);
  }
}

TEST(RigDirectionCheck, OneLensTurnedNinetyDegreesIsNamed) {
  std::mt19937 rng(5);
  const std::vector<Eigen::Matrix3d> ring = Ring(8);
  for (const int wrong : {0, 3, 7}) {
    std::vector<Eigen::Matrix3d> config = ring;
    config[wrong] =
        Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
        config[wrong];
    const std::vector<LensDirection> lenses = CheckRigDirections(
        config, MeasureNeighbours(ring, 2, &rng), RigDirectionCheckOptions());
    for (int lens = 0; lens < 8; ++lens) {
      if (lens == wrong) {
        EXPECT_EQ(lenses[lens].status, LensDirectionStatus::kContradicted);
        ASSERT_TRUE(lenses[lens].measured);
        EXPECT_NEAR(lenses[lens].angle_off_rad / kDeg, 90, 1.5);
      } else {
        EXPECT_EQ(lenses[lens].status, LensDirectionStatus::kConsistent)
            << "lens " << lens << " with lens " << wrong << " wrong";
        EXPECT_LT(lenses[lens].angle_off_rad, 1.5 * kDeg);
      }
    }
  }
}

TEST(RigDirectionCheck, AWrongFrameDoesNotMoveAPair) {
  const std::vector<Eigen::Matrix3d> ring = Ring(2);
  std::vector<LensPairRotation> measurements(3);
  for (LensPairRotation& measurement : measurements) {
    measurement.lens1 = 1;  // given the other way round
    measurement.lens2 = 0;
    measurement.cam2_from_cam1 = ring[0] * ring[1].transpose();
    measurement.num_inliers = 20;
  }
  measurements[2].cam2_from_cam1 =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const std::vector<LensDirection> lenses =
      CheckRigDirections(ring, measurements, RigDirectionCheckOptions());
  for (const LensDirection& lens : lenses) {
    EXPECT_EQ(lens.status, LensDirectionStatus::kConsistent);
    EXPECT_LT(lens.angle_off_rad, 1e-6);
    EXPECT_EQ(lens.num_measurements, 3);
    EXPECT_EQ(lens.num_inliers, 60);
  }
}

// Two lenses that disagree: the later one (not the reference) is named.
TEST(RigDirectionCheck, DualFisheyeNamesTheSecondLens) {
  const std::vector<Eigen::Matrix3d> truth = Ring(2);
  std::vector<Eigen::Matrix3d> config = truth;
  config[1] = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()) *
              Eigen::Matrix3d::Identity();
  LensPairRotation measurement;
  measurement.lens1 = 0;
  measurement.lens2 = 1;
  measurement.cam2_from_cam1 = truth[1] * truth[0].transpose();
  const std::vector<LensDirection> lenses =
      CheckRigDirections(config, {measurement}, RigDirectionCheckOptions());
  EXPECT_EQ(lenses[0].status, LensDirectionStatus::kConsistent);
  EXPECT_FALSE(lenses[0].measured);  // its only partner is named
  EXPECT_EQ(lenses[1].status, LensDirectionStatus::kContradicted);
  EXPECT_NEAR(lenses[1].angle_off_rad / kDeg, 90, 1e-6);
}

TEST(RigDirectionCheck, LensWithoutPairsIsUnchecked) {
  const std::vector<Eigen::Matrix3d> ring = Ring(3);
  LensPairRotation measurement;
  measurement.lens1 = 0;
  measurement.lens2 = 1;
  measurement.cam2_from_cam1 = ring[1] * ring[0].transpose();
  const std::vector<LensDirection> lenses =
      CheckRigDirections(ring, {measurement}, RigDirectionCheckOptions());
  EXPECT_EQ(lenses[0].status, LensDirectionStatus::kConsistent);
  EXPECT_EQ(lenses[2].status, LensDirectionStatus::kUnchecked);
  EXPECT_FALSE(lenses[2].measured);
  measurement.lens2 = 3;
  EXPECT_THROW(
      CheckRigDirections(ring, {measurement}, RigDirectionCheckOptions()),
      std::invalid_argument);
}

TEST(RigDirectionCheck, LensAxisAzimuthAndElevation) {
  const auto cam_from_ref = [](double yaw_deg, double up_deg) {
    // The lens turned YAW about the reference's y axis (z towards x), then
    // its axis raised UP towards -y.
    const Eigen::Matrix3d ref_from_cam =
        (Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(up_deg * M_PI / 180, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    return Eigen::Matrix3d(ref_from_cam.transpose());
  };
  for (const double yaw : {0.0, 45.0, 90.0, 135.0, -45.0, -174.0, 179.5}) {
    for (const double up : {0.0, 5.0, -30.0}) {
      const Eigen::Vector2d axis =
          LensAxisAzimuthElevationDeg(cam_from_ref(yaw, up));
      EXPECT_NEAR(axis.x(), yaw, 1e-9) << yaw << " " << up;
      EXPECT_NEAR(axis.y(), up, 1e-9) << yaw << " " << up;
    }
  }
  // A back lens turned 180 deg about an axis tilted 3 deg from the
  // vertical: its rotation is 180 deg, its axis 6 deg up or down.
  const Eigen::Vector3d tilted(0, std::cos(3 * M_PI / 180),
                               std::sin(3 * M_PI / 180));
  const Eigen::Vector2d back = LensAxisAzimuthElevationDeg(
      Eigen::AngleAxisd(M_PI, tilted).toRotationMatrix());
  EXPECT_NEAR(std::abs(back.x()), 180, 1e-9);
  EXPECT_NEAR(std::abs(back.y()), 6, 1e-9);
}

}  // namespace
}  // namespace sphera
