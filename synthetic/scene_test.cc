#include "synthetic/scene.h"

#include <cmath>

#include <gtest/gtest.h>

namespace sphera {
namespace synthetic {
namespace {

TEST(Scene, RaysHitTheRoomFacesAtTheRightRange) {
  const Scene scene(SceneOptions{});
  RayHit hit;
  ASSERT_TRUE(scene.CastRay(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), &hit));
  EXPECT_NEAR(hit.range, 2.0, 1e-12);
  EXPECT_EQ(scene.Faces()[hit.face_id].axis, 2);
  // -Y is up: the ceiling is 1.5 m above the origin, the floor 1.5 m below.
  ASSERT_TRUE(scene.CastRay(Eigen::Vector3d::Zero(), -Eigen::Vector3d::UnitY(), &hit));
  EXPECT_NEAR(hit.range, 1.5, 1e-12);
  EXPECT_NEAR(hit.point.y(), -1.5, 1e-12);
  ASSERT_TRUE(scene.CastRay(Eigen::Vector3d(0.5, 0.2, -0.3), Eigen::Vector3d::UnitY(), &hit));
  EXPECT_NEAR(hit.range, 1.3, 1e-12);
  // Oblique ray into a room corner region.
  const Eigen::Vector3d direction = Eigen::Vector3d(1, 0, 1).normalized();
  ASSERT_TRUE(scene.CastRay(Eigen::Vector3d(0, -1, 0), direction, &hit));
  EXPECT_NEAR(hit.range, 2 * std::sqrt(2.0), 1e-9);
}

TEST(Scene, BoxesOccludeWalls) {
  const Scene with_boxes(SceneOptions{});
  SceneOptions empty_options;
  empty_options.with_boxes = false;
  const Scene empty(empty_options);
  RayHit hit;
  // The corner cabinet spans x in [1.3, 1.9], y in [0.6, 1.5], z in [1.2, 1.9].
  const Eigen::Vector3d origin(1.6, 0.9, 0.0);
  ASSERT_TRUE(with_boxes.CastRay(origin, Eigen::Vector3d::UnitZ(), &hit));
  EXPECT_NEAR(hit.range, 1.2, 1e-12);
  ASSERT_TRUE(empty.CastRay(origin, Eigen::Vector3d::UnitZ(), &hit));
  EXPECT_NEAR(hit.range, 2.0, 1e-12);
  EXPECT_FALSE(with_boxes.IsFreeSpace(Eigen::Vector3d(1.6, 0.9, 1.5)));
  EXPECT_TRUE(empty.IsFreeSpace(Eigen::Vector3d(1.6, 0.9, 1.5)));
  EXPECT_FALSE(empty.IsFreeSpace(Eigen::Vector3d(0, 1.6, 0)));
  EXPECT_EQ(empty.Faces().size(), 6u);
}

TEST(Scene, EveryRayFromInsideHitsSomething) {
  const Scene scene(SceneOptions{});
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d direction =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    RayHit hit;
    ASSERT_TRUE(scene.CastRay(Eigen::Vector3d(0.1, 0.05, -0.2), direction, &hit));
    EXPECT_GT(hit.range, 0.1);
  }
}

TEST(Scene, ProceduralTextureIsDeterministicAndSeedDependent) {
  SceneOptions options;
  options.seed = 7;
  const Scene a(options), b(options);
  options.seed = 8;
  const Scene c(options);
  double same = 0, different = 0, mean = 0, mean_square = 0, gradient = 0;
  const int n = 200;
  // A 1 m x 1 m patch of the front wall, sampled every 5 mm.
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d p(-0.5 + 0.005 * i, -0.5 + 0.005 * j, 2.0);
      const Eigen::Vector3d q = p + Eigen::Vector3d(0.005, 0, 0);
      const Eigen::Vector3f colour = a.Colour(5, p);
      same += (colour - b.Colour(5, p)).norm();
      different += (colour - c.Colour(5, p)).norm();
      const double luminance = colour.mean();
      mean += luminance;
      mean_square += luminance * luminance;
      gradient += std::abs(luminance - a.Colour(5, q).mean());
    }
  }
  const double samples = n * n;
  EXPECT_EQ(same, 0.0);
  EXPECT_GT(different / samples, 0.2);
  mean /= samples;
  const double stddev = std::sqrt(mean_square / samples - mean * mean);
  EXPECT_GT(stddev, 0.18) << "texture contrast too low for SIFT";
  EXPECT_GT(gradient / samples, 0.02) << "texture lacks fine detail";
}

TEST(Scene, SurfaceSamplesLieOnTheirFace) {
  const Scene scene(SceneOptions{});
  std::mt19937_64 rng(1);
  for (int i = 0; i < 1000; ++i) {
    const RayHit sample = scene.SampleSurfacePoint(&rng);
    const Face& face = scene.Faces()[sample.face_id];
    EXPECT_EQ(sample.point[face.axis], face.offset);
    const Eigen::Vector2d uv = face.UV(sample.point);
    EXPECT_TRUE((uv.array() >= face.min_uv.array()).all() &&
                (uv.array() <= face.max_uv.array()).all());
  }
}

}  // namespace
}  // namespace synthetic
}  // namespace sphera
