// The reprojection error COLMAP filters and reports by is, for a spherical
// camera, the pixel distance bundle adjustment sees: near the rim of a
// lens beyond 180 degrees, tangentially, about 1.6 times what the camera's
// pixels per radian on its axis make of the angle.
#include "colmap_ext/scene/sphere_reprojection_error.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/camera.h"
#include "colmap/scene/projection.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace colmap {
namespace {

Camera MakeCamera(const std::string& model,
                  const std::vector<double>& params,
                  const size_t width,
                  const size_t height) {
  Camera camera;
  camera.camera_id = 1;
  camera.model_id = CameraModelNameToId(model);
  camera.params = params;
  camera.width = width;
  camera.height = height;
  return camera;
}

// Equidistant OPENCV_FISHEYE, f = 300 px, in a 1000 px frame: its image
// circle reaches 95 degrees from the axis, so the camera is spherical.
Camera WholeFieldFisheye() {
  return MakeCamera(
      "OPENCV_FISHEYE", {300, 300, 500, 500, 0, 0, 0, 0}, 1000, 1000);
}

Eigen::Vector3d Direction(const double polar, const double azimuth) {
  return Eigen::Vector3d(std::sin(polar) * std::cos(azimuth),
                         std::sin(polar) * std::sin(azimuth),
                         std::cos(polar));
}

// The squared pixel distance between the observation of DIRECTION and the
// projection of MOVED, and the error COLMAP reports for it.
void ExpectPixelDistance(const Camera& camera,
                         const Eigen::Vector3d& direction,
                         const Eigen::Vector3d& moved,
                         const double relative_tolerance) {
  ASSERT_TRUE(camera.IsSpherical());
  const std::optional<Eigen::Vector2d> observed = camera.ImgFromCam(direction);
  const std::optional<Eigen::Vector2d> projected = camera.ImgFromCam(moved);
  ASSERT_TRUE(observed.has_value());
  ASSERT_TRUE(projected.has_value());
  const double expected = (*projected - *observed).squaredNorm();
  const Rigid3d identity;
  const double error =
      CalculateSquaredReprojectionError(*observed, moved, identity, camera);
  EXPECT_NEAR(error, expected, relative_tolerance * expected);
  const std::optional<double> direct =
      SquaredSphereReprojectionError(camera, *observed, moved);
  ASSERT_TRUE(direct.has_value());
  EXPECT_DOUBLE_EQ(*direct, error);
  // The same through the 3 x 4 matrix.
  EXPECT_DOUBLE_EQ(CalculateSquaredReprojectionError(
                       *observed, moved, identity.ToMatrix(), camera),
                   error);
}

TEST(SphereReprojectionError, IsThePixelDistanceTangentiallyAtTheRim) {
  const Camera camera = WholeFieldFisheye();
  const double polar = 93 * EIGEN_PI / 180;
  const double angle = 1e-3;  // about half a pixel here
  // Along the circle of this polar angle: the geodesic angle `angle` is
  // angle / sin(polar) of azimuth, f polar angle / sin(polar) pixels.
  const Eigen::Vector3d moved =
      Direction(polar, angle / std::sin(polar)).normalized();
  ExpectPixelDistance(camera, Direction(polar, 0), moved, 0.01);
  const double axis_scale = 300;
  const double error = CalculateSquaredReprojectionError(
      *camera.ImgFromCam(Direction(polar, 0)), moved, Rigid3d(), camera);
  // The axis's scale alone would give (300 angle)^2: 2.6 times less.
  EXPECT_GT(error, 2.5 * std::pow(axis_scale * angle, 2));
}

TEST(SphereReprojectionError, IsThePixelDistanceRadially) {
  const Camera camera = WholeFieldFisheye();
  const double polar = 93 * EIGEN_PI / 180;
  ExpectPixelDistance(
      camera, Direction(polar, 0.3), Direction(polar + 2e-3, 0.3), 0.01);
  ExpectPixelDistance(
      camera, Direction(0.2, -1.0), Direction(0.2, -1.0 + 4e-3), 0.01);
}

TEST(SphereReprojectionError, ScalesWithTheDistance) {
  // A point anywhere along the moved direction has the same error.
  const Camera camera = WholeFieldFisheye();
  const Eigen::Vector2d observed = *camera.ImgFromCam(Direction(1.5, 0.7));
  const Eigen::Vector3d moved = Direction(1.5 + 1e-3, 0.7 + 1e-3);
  EXPECT_NEAR(*SquaredSphereReprojectionError(camera, observed, moved),
              *SquaredSphereReprojectionError(camera, observed, 7.5 * moved),
              1e-9);
}

TEST(SphereReprojectionError, EquirectangularKeepsItsOneScale) {
  const Camera camera = MakeCamera("EQUIRECTANGULAR", {2000, 1000}, 2000, 1000);
  ASSERT_TRUE(camera.IsSpherical());
  // Near a pole the pixels of longitude grow without bound; the error stays
  // the angle times W / 2pi.
  const Eigen::Vector3d direction(0.05, 0.99, 0.1);
  const Eigen::Vector3d moved = direction + Eigen::Vector3d(0.002, 0, -0.001);
  const Eigen::Vector2d observed = *camera.ImgFromCam(direction.normalized());
  const double angle =
      std::acos(direction.normalized().dot(moved.normalized()));
  const double expected = std::pow(angle * 2000 / (2 * EIGEN_PI), 2);
  EXPECT_NEAR(
      CalculateSquaredReprojectionError(observed, moved, Rigid3d(), camera),
      expected,
      1e-9 * expected);
}

TEST(SphereReprojectionError, NoneForPerspectiveCamerasOrPixelsWithoutRay) {
  const Camera pinhole = MakeCamera("PINHOLE", {500, 500, 320, 240}, 640, 480);
  EXPECT_FALSE(SquaredSphereReprojectionError(
                   pinhole, Eigen::Vector2d(100, 100), Eigen::Vector3d(0, 0, 1))
                   .has_value());
  // Pinhole errors stay upstream's pixel distance.
  EXPECT_NEAR(CalculateSquaredReprojectionError(Eigen::Vector2d(330, 240),
                                                Eigen::Vector3d(0, 0, 1),
                                                Rigid3d(),
                                                pinhole),
              100,
              1e-9);
  // Equidistant rays reach pi at 942 px from the centre: a pixel beyond
  // has no ray, and the error is the largest angle at the axis's scale.
  const Camera fisheye = WholeFieldFisheye();
  const Eigen::Vector2d far_pixel(500 + 960, 500);
  EXPECT_FALSE(SquaredSphereReprojectionError(
                   fisheye, far_pixel, Eigen::Vector3d(0, 0, 1))
                   .has_value());
  EXPECT_NEAR(CalculateSquaredReprojectionError(
                  far_pixel, Eigen::Vector3d(0, 0, 1), Rigid3d(), fisheye),
              std::pow(EIGEN_PI * 300, 2),
              1e-6);
  // Parameters of the wrong number: none.
  Camera broken = fisheye;
  broken.params.pop_back();
  EXPECT_FALSE(SquaredSphereReprojectionError(
                   broken, Eigen::Vector2d(500, 500), Eigen::Vector3d(0, 0, 1))
                   .has_value());
}

}  // namespace
}  // namespace colmap
