#include "estimators/lens_fit.h"

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "camera_models/registry.h"
#include "estimators/tests/test_utils.h"

namespace sphera {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr int kWidth = 1280;
constexpr int kHeight = 1024;

// A double-sphere lens whose field ends at 126° from the axis (the image
// circle of 115° fits in the frame).
const std::vector<double> kDoubleSphereParams = {200.0, 201.5, 641.3,
                                                 508.7, -0.18, 0.59};

struct BoardScene {
  std::vector<Eigen::Vector3d> board_points;
  std::vector<Eigen::Matrix3d> rotations;  // cam_from_board
  std::vector<Eigen::Vector3d> translations;
};

// A 8 x 6 corner board (4 cm squares) at 0.45 m, centred at the given angles
// from the optical axis (some beyond 90°), facing the camera up to 30° off.
BoardScene MakeBoards(const std::vector<double>& center_angles_deg,
                      std::mt19937* rng) {
  BoardScene scene;
  for (int row = 0; row < 6; ++row) {
    for (int col = 0; col < 8; ++col) {
      scene.board_points.emplace_back(0.04 * col, 0.04 * row, 0.0);
    }
  }
  const Eigen::Vector3d board_center(0.14, 0.10, 0.0);
  std::uniform_real_distribution<double> azimuth(0, 2 * M_PI);
  for (double angle_deg : center_angles_deg) {
    const double theta = angle_deg * kDegToRad;
    const double phi = azimuth(*rng);
    const Eigen::Vector3d direction(std::sin(theta) * std::cos(phi),
                                    std::sin(theta) * std::sin(phi),
                                    std::cos(theta));
    // Board z axis (its normal) points away from the camera, then tilted.
    const Eigen::Matrix3d facing =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), direction)
            .toRotationMatrix();
    const Eigen::Matrix3d rotation =
        test::RandomRotation(rng, 30 * kDegToRad) * facing;
    scene.rotations.push_back(rotation);
    scene.translations.push_back(0.45 * direction - rotation * board_center);
  }
  return scene;
}

std::vector<BoardObservation> Observe(int model_id,
                                      const std::vector<double>& params,
                                      const BoardScene& scene, double noise_px,
                                      std::mt19937* rng) {
  std::normal_distribution<double> noise(0, noise_px);
  std::vector<BoardObservation> observations;
  for (size_t image = 0; image < scene.rotations.size(); ++image) {
    for (const Eigen::Vector3d& point : scene.board_points) {
      const Eigen::Vector3d ray =
          (scene.rotations[image] * point + scene.translations[image])
              .normalized();
      Eigen::Vector2d pixel;
      EXPECT_TRUE(ImageFromRay(model_id, params, ray, &pixel));
      EXPECT_TRUE(pixel.x() > 0 && pixel.x() < kWidth && pixel.y() > 0 &&
                  pixel.y() < kHeight)
          << pixel.transpose();
      BoardObservation observation;
      observation.image_index = static_cast<int>(image);
      observation.point_in_board = point;
      observation.pixel = pixel;
      if (noise_px > 0) {
        observation.pixel += Eigen::Vector2d(noise(*rng), noise(*rng));
      }
      observations.push_back(observation);
    }
  }
  return observations;
}

double MaxRayAngleDeg(const BoardScene& scene) {
  double max_angle = 0;
  for (size_t image = 0; image < scene.rotations.size(); ++image) {
    for (const Eigen::Vector3d& point : scene.board_points) {
      const Eigen::Vector3d ray =
          scene.rotations[image] * point + scene.translations[image];
      max_angle = std::max(
          max_angle, std::atan2(ray.head<2>().norm(), ray.z()) / kDegToRad);
    }
  }
  return max_angle;
}

const std::vector<double> kCenterAnglesDeg = {0, 35, 60, 80, 90, 95};

TEST(BoardPoseFromRays, RecoversPoseOfBoardBeyondNinetyDegrees) {
  std::mt19937 rng(3);
  const BoardScene scene = MakeBoards({110}, &rng);
  std::vector<Eigen::Vector3d> rays;
  int num_behind = 0;
  for (const Eigen::Vector3d& point : scene.board_points) {
    rays.push_back(
        (scene.rotations[0] * point + scene.translations[0]).normalized());
    if (rays.back().z() < 0) ++num_behind;
  }
  ASSERT_GT(num_behind, 24);  // most of the board is behind the image plane
  Eigen::Quaterniond rotation;
  Eigen::Vector3d translation;
  ASSERT_TRUE(
      BoardPoseFromRays(scene.board_points, rays, &rotation, &translation));
  EXPECT_LT((rotation.toRotationMatrix() - scene.rotations[0]).norm(), 1e-9);
  EXPECT_LT((translation - scene.translations[0]).norm(), 1e-9);
}

TEST(BoardPoseFromRays, RefusesCollinearPoints) {
  std::vector<Eigen::Vector3d> points, rays;
  for (int i = 0; i < 6; ++i) {
    points.emplace_back(0.1 * i, 0.0, 0.0);
    rays.push_back(Eigen::Vector3d(0.1 * i, 0.0, 1.0).normalized());
  }
  Eigen::Quaterniond rotation;
  Eigen::Vector3d translation;
  EXPECT_FALSE(BoardPoseFromRays(points, rays, &rotation, &translation));
}

TEST(LensFit, RecoversDoubleSphereFromExactCorners) {
  std::mt19937 rng(7);
  const BoardScene scene = MakeBoards(kCenterAnglesDeg, &rng);
  ASSERT_GT(MaxRayAngleDeg(scene), 100);  // a lens beyond 200°
  const int model_id = static_cast<int>(ModelId::kDoubleSphere);
  const std::vector<BoardObservation> observations =
      Observe(model_id, kDoubleSphereParams, scene, 0.0, &rng);
  const LensFitResult result = FitLens(model_id, kWidth, kHeight, observations);
  EXPECT_EQ(result.status, LensFitStatus::kSuccess) << result.message;
  EXPECT_EQ(result.num_observations, 6 * 48);
  EXPECT_EQ(result.num_not_visible, 0);
  EXPECT_LT(result.rms_error_px, 1e-6);
  ASSERT_EQ(result.params.size(), kDoubleSphereParams.size());
  for (size_t i = 0; i < kDoubleSphereParams.size(); ++i) {
    EXPECT_NEAR(result.params[i], kDoubleSphereParams[i], 1e-6) << i;
  }
  for (size_t image = 0; image < scene.rotations.size(); ++image) {
    EXPECT_LT((result.cam_from_board_rotations[image].toRotationMatrix() -
               scene.rotations[image])
                  .norm(),
              1e-8);
    EXPECT_LT(
        (result.cam_from_board_translations[image] - scene.translations[image])
            .norm(),
        1e-8);
  }
}

TEST(LensFit, NoisyCornersGiveTheNoiseLevel) {
  std::mt19937 rng(11);
  const BoardScene scene = MakeBoards(kCenterAnglesDeg, &rng);
  const int model_id = static_cast<int>(ModelId::kDoubleSphere);
  constexpr double kNoisePx = 0.3;
  const std::vector<BoardObservation> observations =
      Observe(model_id, kDoubleSphereParams, scene, kNoisePx, &rng);
  const LensFitResult result = FitLens(model_id, kWidth, kHeight, observations);
  EXPECT_EQ(result.status, LensFitStatus::kSuccess) << result.message;
  EXPECT_EQ(result.num_not_visible, 0);
  // sqrt(E|r|²) of 2-D Gaussian noise is sqrt(2) sigma, reduced by the
  // 6 + 36 fitted unknowns out of 2 * 288 residuals.
  const double expected_rms =
      std::sqrt(2.0) * kNoisePx * std::sqrt(1.0 - 42.0 / (2 * 288));
  EXPECT_NEAR(result.rms_error_px, expected_rms, 0.1 * expected_rms);
  EXPECT_NEAR(result.params[0], kDoubleSphereParams[0], 1.0);    // fx
  EXPECT_NEAR(result.params[1], kDoubleSphereParams[1], 1.0);    // fy
  EXPECT_NEAR(result.params[2], kDoubleSphereParams[2], 0.5);    // cx
  EXPECT_NEAR(result.params[3], kDoubleSphereParams[3], 0.5);    // cy
  EXPECT_NEAR(result.params[4], kDoubleSphereParams[4], 0.01);   // xi
  EXPECT_NEAR(result.params[5], kDoubleSphereParams[5], 0.003);  // alpha
}

// The same >200° corners fitted by models that cannot describe them: EUCM
// (one parameter fewer) fits worse than DOUBLE_SPHERE, PINHOLE (no ray beyond
// 90°; it sees every corner only through board poses flipped in front of it)
// far worse.
TEST(LensFit, WrongModelFitsWorse) {
  std::mt19937 rng(7);
  const BoardScene scene = MakeBoards(kCenterAnglesDeg, &rng);
  const int double_sphere = static_cast<int>(ModelId::kDoubleSphere);
  const std::vector<BoardObservation> observations =
      Observe(double_sphere, kDoubleSphereParams, scene, 0.0, &rng);
  const LensFitResult right =
      FitLens(double_sphere, kWidth, kHeight, observations);
  const LensFitResult eucm =
      FitLens(static_cast<int>(ModelId::kEUCM), kWidth, kHeight, observations);
  EXPECT_EQ(eucm.num_not_visible, 0);
  EXPECT_GT(eucm.rms_error_px, 0.005);
  EXPECT_GT(eucm.rms_error_px, 1000 * right.rms_error_px);
  const LensFitResult pinhole = FitLens(static_cast<int>(ModelId::kPinhole),
                                        kWidth, kHeight, observations);
  EXPECT_GT(pinhole.rms_error_px, 3.0);
}

TEST(LensFit, RefusesBoardPointsOffThePlane) {
  std::vector<BoardObservation> observations(8);
  observations[3].point_in_board.z() = 0.01;
  EXPECT_THROW(FitLens(static_cast<int>(ModelId::kDoubleSphere), kWidth,
                       kHeight, observations),
               std::invalid_argument);
  EXPECT_THROW(FitLens(static_cast<int>(ModelId::kDoubleSphere), 0, kHeight,
                       std::vector<BoardObservation>()),
               std::invalid_argument);
}

}  // namespace
}  // namespace sphera
