// OCAM (Scaramuzza / OCamCalib): OCamCalib's own unprojection, round trips
// over the whole field (beyond 180°), the fold, the axis, parameter checks and
// autodiff.
#include "camera_models/ocam.h"

#include <ceres/autodiff_cost_function.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "camera_models/model_test_util.h"

namespace sphera {
namespace {

using test::AngleBetween;
using test::RayAt;
using ::testing::HasSubstr;

constexpr double kPi = internal::kPi;
constexpr double kDeg = kPi / 180;

// A polynomial fitted to an equidistant lens of 300 px per radian up to 110°
// (as OCamCalib would): monotone for every radius, so theta reaches 179° at
// rho ~ 2900 px and tends to 180°. Slightly non-identity affine map.
const std::vector<double> kOCam = {812.4, 601.7,   1.0005,  2e-4,  -3e-4,
                                   -300,  1.25e-3, -9.7e-7, 2.5e-9};
// A polynomial that folds: m(rho) = 300 + 1.25e-3 rho² - 1.2e-6 rho³ vanishes
// at rho = 1211.9, theta = 111.1° (a 222° field).
const std::vector<double> kOCamFold = {812.4, 601.7,   1.0005, 2e-4, -3e-4,
                                       -300,  1.25e-3, -6e-7,  0};

// OCamCalib's cam2world, as its ocam_functions.c writes it, for a pixel given
// as (row, col): the affine inverse in (row, col) order, then
// (xp, yp, pol(r)) in its frame (x along rows, y along columns, z backwards).
// Returned in ours (x right, y down, z forward): (yp, xp, -zp).
Eigen::Vector3d OCamCalibCam2World(const std::vector<double>& p, double row,
                                   double col) {
  const double xc = p[1], yc = p[0], c = p[2], d = p[3], e = p[4];
  const double pol[5] = {p[5], 0, p[6], p[7], p[8]};
  const double invdet = 1 / (c - d * e);
  const double xp = invdet * ((row - xc) - d * (col - yc));
  const double yp = invdet * (-e * (row - xc) + c * (col - yc));
  const double r = std::sqrt(xp * xp + yp * yp);
  double zp = pol[0], r_i = 1;
  for (int i = 1; i < 5; ++i) {
    r_i *= r;
    zp += r_i * pol[i];
  }
  return Eigen::Vector3d(yp, xp, -zp).normalized();
}

// Angle of the ray at sensor radius rho, and the first rho where it stops
// increasing, by a dense scan.
double ThetaAt(const std::vector<double>& p, double rho) {
  const double f = p[5] + p[6] * rho * rho + p[7] * rho * rho * rho +
                   p[8] * rho * rho * rho * rho;
  return std::atan2(rho, -f);
}

double FoldByScan(const std::vector<double>& p) {
  constexpr double kStep = 1e-3;
  double previous = 0;
  for (double rho = kStep; rho < 1e5; rho += kStep) {
    const double theta = ThetaAt(p, rho);
    if (!(theta > previous)) return rho - kStep;
    previous = theta;
  }
  return INFINITY;
}

TEST(OCam, FieldOfView) {
  const internal::OCamField fold = OCamModel::FieldOfView(kOCamFold.data());
  EXPECT_TRUE(fold.folds);
  EXPECT_NEAR(fold.rho_max, FoldByScan(kOCamFold), 2e-3);
  EXPECT_NEAR(fold.theta_max, ThetaAt(kOCamFold, fold.rho_max), 1e-15);
  EXPECT_NEAR(fold.theta_max / kDeg, 111.11, 0.01);

  const internal::OCamField open = OCamModel::FieldOfView(kOCam.data());
  EXPECT_FALSE(open.folds);
  EXPECT_EQ(FoldByScan(kOCam), INFINITY);
  EXPECT_EQ(open.theta_max, kPi);
  EXPECT_EQ(open.rho_max, INFINITY);

  const std::vector<double> pinhole = OCamModel::InitialParams(500, 1000, 800);
  EXPECT_EQ(OCamModel::FieldOfView(pinhole.data()).theta_max, kPi / 2);
}

// The unprojection is OCamCalib's cam2world, in our axes.
TEST(OCam, RayFromImageIsOCamCalibCam2World) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> col(-800, 2400), row(-600, 1800);
  int num_tested = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector2d pixel(col(rng), row(rng));
    Eigen::Vector3d ray;
    ASSERT_TRUE(
        OCamModel::RayFromImage(kOCam.data(), pixel.data(), ray.data()));
    EXPECT_LT(
        AngleBetween(ray, OCamCalibCam2World(kOCam, pixel.y(), pixel.x())),
        1e-14);
    ++num_tested;
  }
  EXPECT_EQ(num_tested, 2000);
  // The distortion centre is the optical axis.
  Eigen::Vector3d ray;
  const Eigen::Vector2d centre(kOCam[0], kOCam[1]);
  ASSERT_TRUE(OCamModel::RayFromImage(kOCam.data(), centre.data(), ray.data()));
  EXPECT_EQ(ray, Eigen::Vector3d(0, 0, 1));
}

// Rays up to 179° (kOCam) and up to 1e-6 rad short of the fold (kOCamFold),
// all azimuths, come back from their pixels within 1e-9 rad.
TEST(OCam, RayPixelRayRoundTripBeyond180Degrees) {
  for (const std::vector<double>& params : {kOCam, kOCamFold}) {
    const internal::OCamField field = OCamModel::FieldOfView(params.data());
    const double max_theta = field.folds ? field.theta_max - 1e-6 : 179 * kDeg;
    double max_error = 0;
    int num_failed = 0;
    for (int i = 0; i <= 400; ++i) {
      const double theta = max_theta * i / 400;
      for (int j = 0; j < 96; ++j) {
        const Eigen::Vector3d ray = RayAt(theta, 2 * kPi * j / 96);
        Eigen::Vector2d pixel;
        Eigen::Vector3d back;
        if (!OCamModel::ImageFromRay(params.data(), ray.data(), pixel.data()) ||
            !OCamModel::RayFromImage(params.data(), pixel.data(),
                                     back.data())) {
          ++num_failed;
          continue;
        }
        max_error = std::max(max_error, AngleBetween(ray, back));
      }
    }
    EXPECT_EQ(num_failed, 0) << field.folds;
    EXPECT_LT(max_error, 1e-9) << field.folds;
  }
}

// The rescaled parameters put every ray at the scaled pixel, for an aspect
// change too, and the scaled image keeps the field of view.
TEST(OCam, RescaleScalesEveryPixel) {
  for (const auto& [scale_x, scale_y] :
       {std::pair{0.5, 0.5}, std::pair{2.0, 2.0}, std::pair{0.5, 0.4}}) {
    std::vector<double> scaled = kOCamFold;
    OCamModel::Rescale(scale_x, scale_y, scaled.data());
    const double theta_max =
        OCamModel::FieldOfView(kOCamFold.data()).theta_max;
    EXPECT_NEAR(OCamModel::FieldOfView(scaled.data()).theta_max, theta_max,
                1e-9);
    for (const double theta : {0.0, 0.3, 1.2, 1.9}) {
      for (const double azimuth : {0.0, 1.0, 2.5, -2.0}) {
        const Eigen::Vector3d ray = RayAt(theta, azimuth);
        Eigen::Vector2d pixel, scaled_pixel;
        ASSERT_TRUE(OCamModel::ImageFromRay(kOCamFold.data(), ray.data(),
                                            pixel.data()));
        ASSERT_TRUE(OCamModel::ImageFromRay(scaled.data(), ray.data(),
                                            scaled_pixel.data()));
        EXPECT_NEAR(scaled_pixel.x(), scale_x * pixel.x(), 1e-7);
        EXPECT_NEAR(scaled_pixel.y(), scale_y * pixel.y(), 1e-7);
      }
    }
  }
}

TEST(OCam, PixelRayPixelRoundTrip) {
  for (const std::vector<double>& params : {kOCam, kOCamFold}) {
    const internal::OCamField field = OCamModel::FieldOfView(params.data());
    double max_error = 0;
    int num_tested = 0, num_failed = 0;
    for (double px = -600; px <= 2200; px += 9.7) {
      for (double py = -600; py <= 1800; py += 9.3) {
        const Eigen::Vector2d pixel(px, py);
        // The sensor radius by OCamCalib's formula (row, col order).
        const double det = params[2] - params[3] * params[4];
        const double s_row =
            ((py - params[1]) - params[3] * (px - params[0])) / det;
        const double s_col =
            (-params[4] * (py - params[1]) + params[2] * (px - params[0])) /
            det;
        if (std::hypot(s_row, s_col) > 0.999 * field.rho_max) continue;
        ++num_tested;
        Eigen::Vector3d ray;
        Eigen::Vector2d back;
        if (!OCamModel::RayFromImage(params.data(), pixel.data(), ray.data()) ||
            !OCamModel::ImageFromRay(params.data(), ray.data(), back.data())) {
          ++num_failed;
          continue;
        }
        max_error = std::max(max_error, (back - pixel).norm());
      }
    }
    EXPECT_GT(num_tested, 40000) << field.folds;
    EXPECT_EQ(num_failed, 0) << field.folds;
    EXPECT_LT(max_error, 1e-9) << field.folds;
  }
}

TEST(OCam, NotVisibleBeyondTheFold) {
  const internal::OCamField field = OCamModel::FieldOfView(kOCamFold.data());
  Eigen::Vector2d pixel;
  for (double phi = 0; phi < 2 * kPi; phi += 10 * kDeg) {
    const Eigen::Vector3d inside = RayAt(field.theta_max - 1e-4, phi);
    EXPECT_TRUE(
        OCamModel::ImageFromRay(kOCamFold.data(), inside.data(), pixel.data()));
    for (double theta = field.theta_max + 1e-4; theta <= kPi;
         theta += 3 * kDeg) {
      const Eigen::Vector3d ray = RayAt(theta, phi);
      EXPECT_FALSE(
          OCamModel::ImageFromRay(kOCamFold.data(), ray.data(), pixel.data()))
          << theta / kDeg;
    }
  }
  // Pixels past the fold radius (along the columns, c d e ~ identity).
  for (double scale : {1.001, 1.2, 4.0}) {
    const Eigen::Vector2d outside(kOCamFold[0] + scale * field.rho_max,
                                  kOCamFold[1]);
    Eigen::Vector3d ray;
    EXPECT_FALSE(
        OCamModel::RayFromImage(kOCamFold.data(), outside.data(), ray.data()))
        << scale;
  }
}

TEST(OCam, AxisRays) {
  for (const std::vector<double>& params : {kOCam, kOCamFold}) {
    const Eigen::Vector3d forward(0, 0, 3), backward(0, 0, -1), zero(0, 0, 0);
    Eigen::Vector2d pixel;
    ASSERT_TRUE(
        OCamModel::ImageFromRay(params.data(), forward.data(), pixel.data()));
    EXPECT_EQ(pixel, Eigen::Vector2d(params[0], params[1]));
    EXPECT_FALSE(
        OCamModel::ImageFromRay(params.data(), backward.data(), pixel.data()));
    EXPECT_FALSE(
        OCamModel::ImageFromRay(params.data(), zero.data(), pixel.data()));
    // Near the axis a pixel is ~ -a0 radians^-1.
    for (double theta : {1e-12, 1e-6, 1e-3}) {
      const Eigen::Vector3d ray = RayAt(theta, 0);
      ASSERT_TRUE(
          OCamModel::ImageFromRay(params.data(), ray.data(), pixel.data()));
      EXPECT_NEAR(pixel.x() - params[0], 300 * theta, 1e-3 * 300 * theta);
    }
  }
  // Without a fold rays 1° from the backward axis are still visible.
  Eigen::Vector2d pixel;
  const Eigen::Vector3d behind = RayAt(179 * kDeg, 1.0);
  EXPECT_TRUE(
      OCamModel::ImageFromRay(kOCam.data(), behind.data(), pixel.data()));
}

TEST(OCam, InitialParamsArePinhole) {
  const std::vector<double> params = OCamModel::InitialParams(500, 1000, 800);
  EXPECT_EQ(OCamModel::CheckParams(params, 1000, 800), "");
  const Eigen::Vector3d ray(0.3, -0.2, 0.9);
  Eigen::Vector2d pixel;
  ASSERT_TRUE(OCamModel::ImageFromRay(params.data(), ray.data(), pixel.data()));
  EXPECT_NEAR(pixel.x(), 500 + 500 * 0.3 / 0.9, 1e-9);
  EXPECT_NEAR(pixel.y(), 400 - 500 * 0.2 / 0.9, 1e-9);
  const Eigen::Vector3d sideways(1, 0, 0), behind(0.3, 0.1, -0.5);
  EXPECT_FALSE(
      OCamModel::ImageFromRay(params.data(), sideways.data(), pixel.data()));
  EXPECT_FALSE(
      OCamModel::ImageFromRay(params.data(), behind.data(), pixel.data()));
  EXPECT_NEAR(OCamModel::PixelToAngle(params.data()), 1.0 / 500, 1e-15);
}

TEST(OCam, CheckParams) {
  EXPECT_EQ(OCamModel::CheckParams(kOCam, 1624, 1203), "");
  EXPECT_EQ(OCamModel::CheckParams(kOCam, 0, 0), "");
  // The fold at rho = 1211.9 lies beyond the image circle of a 1624 x 1203
  // image and inside that of a 2600 x 2000 one (1788 px to its right edge).
  EXPECT_EQ(OCamModel::CheckParams(kOCamFold, 1624, 1203), "");
  EXPECT_EQ(OCamModel::CheckParams(kOCamFold, 0, 0), "");
  const std::string message = OCamModel::CheckParams(kOCamFold, 2600, 2000);
  EXPECT_THAT(message, HasSubstr("OCAM: projection folds at 111.1° (r = 121"));
  EXPECT_THAT(message, HasSubstr("inside the image circle of the 2600x2000 "
                                 "image (radius 17"));

  std::vector<double> params = kOCam;
  params[5] = 300;
  EXPECT_THAT(OCamModel::CheckParams(params, 0, 0),
              HasSubstr("OCAM: a0=300 must be negative"));
  params = kOCam;
  params[2] = 0.5;
  params[3] = 1;
  params[4] = 1;
  EXPECT_THAT(OCamModel::CheckParams(params, 0, 0),
              HasSubstr("OCAM: c - d e = -0.5"));
  params = kOCam;
  params[7] = NAN;
  EXPECT_THAT(OCamModel::CheckParams(params, 0, 0), HasSubstr("a3=nan"));
  EXPECT_THAT(OCamModel::CheckParams({1, 2, 3}, 0, 0),
              HasSubstr("OCAM: expected 9 params"));
}

TEST(OCam, AutodiffMatchesCentralDifferences) {
  // Away from the axis coefficients from 1 to 1e-9 need steps of their own
  // scale; near it they hardly matter and a small step would only measure
  // rounding.
  const std::vector<double> far_steps = {1e-3, 1e-3, 1e-6,  1e-6, 1e-6,
                                         1e-3, 1e-9, 1e-12, 1e-15};
  struct Case {
    std::vector<double> params;
    Eigen::Vector3d ray;
  };
  for (const Case& c : {Case{kOCam, RayAt(0, 0)}, Case{kOCam, RayAt(1e-7, 0.4)},
                        Case{kOCam, RayAt(35 * kDeg, 1.3)},
                        Case{kOCam, RayAt(100 * kDeg, -2.2)},
                        Case{kOCam, RayAt(150 * kDeg, 2.8)},
                        Case{kOCamFold, RayAt(110 * kDeg, 0.6)}}) {
    SCOPED_TRACE(::testing::Message() << "ray " << c.ray.transpose());
    const std::vector<double>& params = c.params;
    const Eigen::Vector3d& ray = c.ray;
    const std::vector<double> steps =
        ray.z() > 0.99 ? std::vector<double>() : far_steps;
    test::ExpectAutodiffMatchesCentralDifferences<OCamModel>(params, ray,
                                                             steps);
  }
}

}  // namespace
}  // namespace sphera
