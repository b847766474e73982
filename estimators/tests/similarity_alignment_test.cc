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

// Two models of one scene: src, and tgt = s R src + t. `num_frames` frames
// far from both world origins, `num_points` points each, of which every
// fourth is moved along its ray (a badly triangulated point) in tgt.
std::vector<SharedRigFrame> SharedFrames(std::mt19937* rng,
                                         const double scale,
                                         const Eigen::Matrix3d& R,
                                         const Eigen::Vector3d& t,
                                         const int num_frames,
                                         const int num_points) {
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::vector<SharedRigFrame> frames;
  for (int f = 0; f < num_frames; ++f) {
    SharedRigFrame frame;
    frame.src_rotation = RandomRotation(rng, 3.0);
    const Eigen::Vector3d src_center(20 + uniform(*rng), 5 * uniform(*rng),
                                     -10 + uniform(*rng));
    frame.src_translation = -frame.src_rotation * src_center;
    // rig_from_tgt_world = rig_from_src_world (scaled) * src_from_tgt_world.
    frame.tgt_rotation = frame.src_rotation * R.transpose();
    const Eigen::Vector3d tgt_center = scale * R * src_center + t;
    frame.tgt_translation = -frame.tgt_rotation * tgt_center;
    for (int i = 0; i < num_points; ++i) {
      const Eigen::Vector3d src_point =
          src_center + (3 + 2 * uniform(*rng)) *
                           Eigen::Vector3d(uniform(*rng), uniform(*rng),
                                           uniform(*rng)).normalized();
      Eigen::Vector3d tgt_point = scale * R * src_point + t;
      if (i % 4 == 3) {
        tgt_point = tgt_center + (1.5 + uniform(*rng)) * (tgt_point - tgt_center);
      }
      frame.src_tgt_points.emplace_back(src_point, tgt_point);
    }
    frames.push_back(frame);
  }
  return frames;
}

TEST(AlignViaSharedRigFrames, RecoversTheSimilarityDespiteBadPoints) {
  std::mt19937 rng(11);
  const double scale = 0.37;
  const Eigen::Matrix3d R = RandomRotation(&rng, 3.0);
  const Eigen::Vector3d t(4, -7, 2);
  for (const int num_frames : {1, 3}) {
    const std::vector<SharedRigFrame> frames =
        SharedFrames(&rng, scale, R, t, num_frames, /*num_points=*/9);
    SharedFrameAlignment alignment;
    ASSERT_TRUE(AlignViaSharedRigFrames(frames, /*min_points=*/5, 0, &alignment));
    EXPECT_NEAR(alignment.scale, scale, 1e-12);
    EXPECT_LT(AngleDeg(alignment.rotation, R), 1e-9);
    EXPECT_LT((alignment.translation - t).norm(), 1e-9);
    EXPECT_EQ(alignment.num_points, 9 * num_frames);
    // Two of nine points are off: the median deviation stays zero.
    EXPECT_LT(alignment.log_scale_spread, 1e-12);
  }
}

TEST(AlignViaSharedRigFrames, ScaleSpreadGrowsWithDisagreeingPoints) {
  std::mt19937 rng(13);
  const Eigen::Matrix3d R = RandomRotation(&rng, 3.0);
  std::vector<SharedRigFrame> frames = SharedFrames(
      &rng, 2.0, R, Eigen::Vector3d(1, 2, 3), /*num_frames=*/1, 8);
  std::uniform_real_distribution<double> factor(0.5, 2.0);
  for (auto& [src_point, tgt_point] : frames[0].src_tgt_points) {
    tgt_point *= factor(rng);
  }
  SharedFrameAlignment alignment;
  ASSERT_TRUE(AlignViaSharedRigFrames(frames, 5, 0, &alignment));
  EXPECT_GT(alignment.log_scale_spread, 0.05);
}

TEST(AlignViaSharedRigFrames, TooFewPointsTakeTheFallbackScale) {
  std::mt19937 rng(19);
  const Eigen::Matrix3d R = RandomRotation(&rng, 3.0);
  const Eigen::Vector3d t(-3, 1, 8);
  std::vector<SharedRigFrame> frames =
      SharedFrames(&rng, 2.5, R, t, /*num_frames=*/2, /*num_points=*/2);
  SharedFrameAlignment alignment;
  ASSERT_TRUE(AlignViaSharedRigFrames(frames, 5, 2.5, &alignment));
  EXPECT_EQ(alignment.num_points, 0);
  EXPECT_EQ(alignment.scale, 2.5);
  EXPECT_LT(AngleDeg(alignment.rotation, R), 1e-9);
  EXPECT_LT((alignment.translation - t).norm(), 1e-9);
  // Enough points: theirs, not the fallback.
  ASSERT_TRUE(AlignViaSharedRigFrames(frames, 3, 7.0, &alignment));
  EXPECT_EQ(alignment.num_points, 4);
  EXPECT_NEAR(alignment.scale, 2.5, 1e-12);
}

TEST(AlignViaSharedRigFrames, RefusesTooFewPoints) {
  std::mt19937 rng(17);
  SharedFrameAlignment alignment;
  EXPECT_FALSE(AlignViaSharedRigFrames({}, 0, 1.0, &alignment));
  std::vector<SharedRigFrame> frames =
      SharedFrames(&rng, 1.0, Eigen::Matrix3d::Identity(),
                   Eigen::Vector3d::Zero(), /*num_frames=*/1, 4);
  EXPECT_FALSE(AlignViaSharedRigFrames(frames, 5, 0, &alignment));
  EXPECT_TRUE(AlignViaSharedRigFrames(frames, 4, 0, &alignment));
  // A point at a frame's origin says nothing about the scale.
  frames[0].src_tgt_points[0].first =
      -frames[0].src_rotation.transpose() * frames[0].src_translation;
  EXPECT_FALSE(AlignViaSharedRigFrames(frames, 4, 0, &alignment));
}

}  // namespace
}  // namespace sphera
