// Pixel conventions of EQUIRECTANGULAR, shared with upstream COLMAP 4.1.
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "camera_models/equirectangular.h"

namespace sphera {
namespace {

constexpr double kW = 2048;
constexpr double kH = 1024;
const std::vector<double> kParams = {kW, kH};

Eigen::Vector2d Project(const Eigen::Vector3d& ray) {
  Eigen::Vector2d pixel;
  EXPECT_TRUE(
      EquirectangularModel::ImageFromRay(kParams.data(), ray.data(), pixel.data()));
  return pixel;
}

Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) {
  Eigen::Vector3d ray;
  EXPECT_TRUE(
      EquirectangularModel::RayFromImage(kParams.data(), pixel.data(), ray.data()));
  return ray;
}

TEST(Equirectangular, AxesMapToDocumentedPixels) {
  EXPECT_TRUE(Project({0, 0, 1}).isApprox(Eigen::Vector2d(kW / 2, kH / 2)));
  EXPECT_TRUE(Project({1, 0, 0}).isApprox(Eigen::Vector2d(0.75 * kW, 0.5 * kH)));
  EXPECT_TRUE(Project({-1, 0, 0}).isApprox(Eigen::Vector2d(0.25 * kW, 0.5 * kH)));
  EXPECT_NEAR(Project({0, -1, 0}).y(), 0, 1e-12);   // up (-y) is the top row
  EXPECT_NEAR(Project({0, 1, 0}).y(), kH, 1e-12);   // down is the bottom row
  EXPECT_NEAR(Project({0, 0, -1}).x(), kW, 1e-12);  // atan2(+0, -1) = pi
  EXPECT_NEAR(Project({-0.0, 0, -1}).x(), 0, 1e-12);
  // Latitude 45 deg up at longitude 0.
  const Eigen::Vector2d up45 = Project({0, -1, 1});
  EXPECT_NEAR(up45.x(), kW / 2, 1e-9);
  EXPECT_NEAR(up45.y(), kH / 4, 1e-9);
}

TEST(Equirectangular, PixelsMapToDocumentedRays) {
  EXPECT_TRUE(Unproject({kW / 2, kH / 2}).isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_TRUE(
      Unproject({0.75 * kW, kH / 2}).isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_LT((Unproject({123.4, 0}) - Eigen::Vector3d(0, -1, 0)).norm(), 1e-12);
  EXPECT_LT((Unproject({1500, kH}) - Eigen::Vector3d(0, 1, 0)).norm(), 1e-12);
  // Both image borders are the -z half plane (the seam).
  EXPECT_LT((Unproject({0, kH / 2}) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-12);
  EXPECT_LT((Unproject({kW, kH / 2}) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-12);
}

TEST(Equirectangular, PolesAndSeamRoundTrip) {
  for (const Eigen::Vector3d& ray :
       {Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 1, 0),
        Eigen::Vector3d(0, 0.3, -1), Eigen::Vector3d(-0.0, 0.3, -1),
        Eigen::Vector3d(1e-12, -0.7, -1), Eigen::Vector3d(-1e-12, 0.7, -1),
        Eigen::Vector3d(1e-9, -1, 1e-9)}) {
    const Eigen::Vector3d back = Unproject(Project(ray));
    const Eigen::Vector3d unit = ray.normalized();
    EXPECT_LT(std::atan2(unit.cross(back).norm(), unit.dot(back)), 1e-12)
        << ray.transpose();
  }
}

TEST(Equirectangular, PixelToAngleIsLongitudeStep) {
  EXPECT_DOUBLE_EQ(EquirectangularModel::PixelToAngle(kParams.data()),
                   2 * internal::kPi / kW);
}

TEST(Equirectangular, InitialParamsAreImageSize) {
  EXPECT_EQ(EquirectangularModel::InitialParams(1234, 5376, 2688),
            (std::vector<double>{5376, 2688}));
}

}  // namespace
}  // namespace sphera
