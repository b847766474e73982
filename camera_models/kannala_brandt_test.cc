// OPENCV_FISHEYE and THIN_PRISM_FISHEYE over the whole field of view: round
// trips beyond 180°, upstream COLMAP's formulas for z > 0, the fold, the axis,
// parameter checks and autodiff.
#include "camera_models/kannala_brandt.h"

#include <ceres/autodiff_cost_function.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "camera_models/model_test_util.h"

namespace sphera {
namespace {

using test::AngleBetween;
using test::RayAt;
using ::testing::HasSubstr;

constexpr double kPi = internal::kPi;
constexpr double kDeg = kPi / 180;

// A 210° lens: the fitted polynomial turns over at 105.44° (r = 1.5567 f),
// so the image circle of a 640 x 640 image (320 px about the centre, fold
// at 467 px) holds no fold and that of a 1600 x 1088 one does.
const std::vector<double> kFisheye = {300.5, 300.1, 320.3,  320.2,
                                      0.015, -0.01, -0.003, 0.0002};
// The same radial terms with tangential and thin-prism terms.
const std::vector<double> kThinPrism = {300.5,  300.1,  320.3, 320.2,
                                        0.015,  -0.01,  2e-4,  -1.5e-4,
                                        -0.003, 0.0002, 3e-4,  -2e-4};
// Equidistant (no fold): the field reaches the backward axis.
const std::vector<double> kEquidistant = {300, 300, 320, 320, 0, 0, 0, 0};

// dr/dtheta of the Kannala-Brandt polynomial, written out independently.
double Slope(const std::vector<double>& k4, double theta) {
  const double t2 = theta * theta;
  return 1 + 3 * k4[0] * t2 + 5 * k4[1] * t2 * t2 + 7 * k4[2] * t2 * t2 * t2 +
         9 * k4[3] * t2 * t2 * t2 * t2;
}

// First theta where dr/dtheta <= 0 by a dense scan (pi if none).
double FoldByScan(const std::vector<double>& k4) {
  constexpr double kStep = 1e-6;
  for (double theta = 0; theta < kPi; theta += kStep) {
    if (Slope(k4, theta) <= 0) return theta;
  }
  return kPi;
}

// Upstream COLMAP's OPENCV_FISHEYE projection of (x, y, z), z > 0, as its
// sensor/models.h states it: normalized point, theta = atan(r), theta-scaled
// point, radial distortion of it, focal and principal point.
Eigen::Vector2d UpstreamOpenCVFisheye(const std::vector<double>& p,
                                      const Eigen::Vector3d& ray) {
  double u = ray.x() / ray.z(), v = ray.y() / ray.z();
  const double r = std::sqrt(u * u + v * v);
  if (r > std::numeric_limits<double>::epsilon()) {
    const double theta = std::atan(r);
    u *= theta / r;
    v *= theta / r;
  }
  const double t2 = u * u + v * v;
  const double radial = p[4] * t2 + p[5] * t2 * t2 + p[6] * t2 * t2 * t2 +
                        p[7] * t2 * t2 * t2 * t2;
  return {p[0] * (u + u * radial) + p[2], p[1] * (v + v * radial) + p[3]};
}

// Upstream's THIN_PRISM_FISHEYE, params fx, fy, cx, cy, k1, k2, p1, p2, k3, k4,
// sx1, sy1, on the same theta-scaled point.
Eigen::Vector2d UpstreamThinPrismFisheye(const std::vector<double>& p,
                                         const Eigen::Vector3d& ray) {
  double u = ray.x() / ray.z(), v = ray.y() / ray.z();
  const double r = std::sqrt(u * u + v * v);
  if (r > std::numeric_limits<double>::epsilon()) {
    const double theta = std::atan(r);
    u *= theta / r;
    v *= theta / r;
  }
  const double k1 = p[4], k2 = p[5], p1 = p[6], p2 = p[7], k3 = p[8], k4 = p[9],
               sx1 = p[10], sy1 = p[11];
  const double r2 = u * u + v * v;
  const double radial =
      k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2 + k4 * r2 * r2 * r2 * r2;
  const double du =
      u * radial + 2 * p1 * u * v + p2 * (r2 + 2 * u * u) + sx1 * r2;
  const double dv =
      v * radial + 2 * p2 * u * v + p1 * (r2 + 2 * v * v) + sy1 * r2;
  return {p[0] * (u + du) + p[2], p[1] * (v + dv) + p[3]};
}

template <typename Model>
std::vector<double> RadialTerms(const std::vector<double>& params) {
  if (Model::kModelId == OpenCVFisheyeModel::kModelId) {
    return {params[4], params[5], params[6], params[7]};
  }
  return {params[4], params[5], params[8], params[9]};
}

// Where the visible field ends at azimuth phi: the radial fold, or for
// THIN_PRISM_FISHEYE the first theta before it where the distortion's
// Jacobian determinant (by central differences) stops being positive.
template <typename Model>
double FieldLimitAt(const std::vector<double>& params, double phi) {
  const double theta_max = FoldByScan(RadialTerms<Model>(params));
  if (Model::kModelId == OpenCVFisheyeModel::kModelId) return theta_max;
  const auto det = [&](double theta) {
    const auto distort = [&](const std::vector<double>& x) {
      Eigen::VectorXd out(2);
      internal::ThinPrismDistortion(params.data() + 4, x[0], x[1], &out[0],
                                    &out[1]);
      return out;
    };
    return test::CentralDifferences(
               distort, {theta * std::cos(phi), theta * std::sin(phi)}, 2,
               {1e-5, 1e-5})
        .determinant();
  };
  double lo = 0;
  for (int step = 1; lo < theta_max; ++step) {
    const double theta = std::min(1e-3 * step, theta_max);
    if (det(theta) <= 0) {
      double hi = theta;
      for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        (det(mid) > 0 ? lo : hi) = mid;
      }
      return hi;
    }
    lo = theta;
  }
  return theta_max;
}

TEST(KannalaBrandtFieldOfView, FoldMatchesDenseScan) {
  const std::vector<double> k = RadialTerms<OpenCVFisheyeModel>(kFisheye);
  const internal::KannalaBrandtField field =
      OpenCVFisheyeModel::FieldOfView(kFisheye.data());
  EXPECT_TRUE(field.folds);
  EXPECT_NEAR(field.theta_max, FoldByScan(k), 2e-6);
  // A 210.9° lens.
  EXPECT_NEAR(2 * field.theta_max / kDeg, 210.88, 0.01);
  EXPECT_NEAR(Slope(k, field.theta_max), 0, 1e-12);

  const internal::KannalaBrandtField none =
      OpenCVFisheyeModel::FieldOfView(kEquidistant.data());
  EXPECT_FALSE(none.folds);
  EXPECT_EQ(none.theta_max, kPi);

  // Several coefficient sets of real-lens magnitude, folding or not.
  for (const std::vector<double>& other :
       std::vector<std::vector<double>>{{-0.01, 0.002, -0.0015, 0.0001},
                                        {0.02, -0.01, -0.004, 0},
                                        {-0.012, -0.006, -0.003, 0.0002},
                                        {-0.013, 0.0035, -0.0022, 0.00025},
                                        {-0.3, 0, 0, 0}}) {
    const internal::KannalaBrandtField f =
        internal::KannalaBrandtFieldOfView(other.data());
    const double scan = FoldByScan(other);
    EXPECT_NEAR(f.theta_max, scan, 2e-6) << other[0] << " " << other[1];
    EXPECT_EQ(f.folds, scan < kPi) << other[0] << " " << other[1];
  }
}

// The answers are kept per thread for a few lenses: asked in turn, more
// lenses than it keeps and back, each lens gets its own field every time.
TEST(KannalaBrandtFieldOfView, LensesAskedInTurnGetTheirOwnField) {
  std::vector<std::vector<double>> lenses;
  std::vector<double> scans;
  for (int i = 0; i < 12; ++i) {
    lenses.push_back({-0.01 - 0.001 * i, 0.002, -0.0015, 0.0001});
    scans.push_back(FoldByScan(lenses.back()));
  }
  for (int round = 0; round < 3; ++round) {
    for (size_t count : {2u, 12u}) {
      for (size_t i = 0; i < count; ++i) {
        EXPECT_NEAR(internal::KannalaBrandtFieldOfView(lenses[i].data())
                        .theta_max,
                    scans[i], 2e-6)
            << "lens " << i << " of " << count << ", round " << round;
      }
    }
  }
  EXPECT_LT(scans[0], kPi);
  EXPECT_GT(scans[0] - scans[11], 0.01);  // the lenses differ
}

template <typename Model>
class KannalaBrandtTest : public ::testing::Test {
 protected:
  static std::vector<double> Params() {
    return Model::kModelId == OpenCVFisheyeModel::kModelId ? kFisheye
                                                           : kThinPrism;
  }
};

using Models = ::testing::Types<OpenCVFisheyeModel, ThinPrismFisheyeModel>;
TYPED_TEST_SUITE(KannalaBrandtTest, Models);

// Every ray up to 1e-6 rad short of the fold, over all azimuths, comes back
// from its pixel within 1e-9 rad.
TYPED_TEST(KannalaBrandtTest, RayPixelRayRoundTripBeyond180Degrees) {
  using Model = TypeParam;
  const std::vector<double> params = this->Params();
  constexpr int kNumTheta = 400;
  constexpr int kNumPhi = 96;
  double max_error = 0, min_limit = kPi;
  int num_failed = 0;
  Eigen::Vector3d worst = Eigen::Vector3d::Zero();
  for (int j = 0; j < kNumPhi; ++j) {
    const double phi = 2 * kPi * j / kNumPhi;
    const double limit = FieldLimitAt<Model>(params, phi);
    min_limit = std::min(min_limit, limit);
    for (int i = 0; i <= kNumTheta; ++i) {
      const double theta = (limit - 1e-6) * i / kNumTheta;
      const Eigen::Vector3d ray = RayAt(theta, phi);
      Eigen::Vector2d pixel;
      Eigen::Vector3d back;
      if (!Model::ImageFromRay(params.data(), ray.data(), pixel.data()) ||
          !Model::RayFromImage(params.data(), pixel.data(), back.data())) {
        ++num_failed;
        worst = ray;
        continue;
      }
      EXPECT_NEAR(back.norm(), 1, 1e-12);
      const double error = AngleBetween(ray, back);
      if (!(error <= max_error)) {
        max_error = error;
        worst = ray;
      }
    }
  }
  // Both lenses see more than 210°.
  EXPECT_GT(2 * min_limit, 210 * kDeg);
  EXPECT_EQ(num_failed, 0) << "last failure " << worst.transpose();
  EXPECT_LT(max_error, 1e-9) << "worst ray " << worst.transpose();
  this->RecordProperty("max_error_rad", std::to_string(max_error));
}

// Every pixel whose radius is inside the fold (here up to 0.999 of the fold
// radius, a disc of 934 px across) maps back to itself.
TYPED_TEST(KannalaBrandtTest, PixelRayPixelRoundTrip) {
  using Model = TypeParam;
  const std::vector<double> params = this->Params();
  const std::vector<double> k = RadialTerms<Model>(params);
  const double theta_max = Model::FieldOfView(params.data()).theta_max;
  const double r_max = internal::KannalaBrandtRadius(k.data(), theta_max);
  double max_error = 0;
  int num_tested = 0, num_failed = 0;
  for (double px = -200; px <= 840; px += 4.1) {
    for (double py = -200; py <= 840; py += 4.3) {
      const double r = std::hypot((px - params[2]) / params[0],
                                  (py - params[3]) / params[1]);
      if (r > 0.999 * r_max) continue;
      ++num_tested;
      const Eigen::Vector2d pixel(px, py);
      Eigen::Vector3d ray;
      Eigen::Vector2d back;
      if (!Model::RayFromImage(params.data(), pixel.data(), ray.data()) ||
          !Model::ImageFromRay(params.data(), ray.data(), back.data())) {
        ++num_failed;
        continue;
      }
      max_error = std::max(max_error, (back - pixel).norm());
    }
  }
  EXPECT_GT(num_tested, 30000);
  EXPECT_EQ(num_failed, 0);
  EXPECT_LT(max_error, 1e-9);
}

// For z > 0 the projection is upstream COLMAP's, to rounding.
TYPED_TEST(KannalaBrandtTest, EqualsUpstreamFormulaInFrontOfTheLens) {
  using Model = TypeParam;
  const std::vector<double> params = this->Params();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0, 1);
  double max_error = 0;
  for (int i = 0; i < 2000; ++i) {
    // Polar angles from 0 to 89.9° with many near the axis.
    const double theta = 89.9 * kDeg * std::pow(unit(rng), 3);
    const Eigen::Vector3d ray =
        (0.5 + unit(rng)) * RayAt(theta, 2 * kPi * unit(rng));
    Eigen::Vector2d pixel;
    ASSERT_TRUE(Model::ImageFromRay(params.data(), ray.data(), pixel.data()));
    const Eigen::Vector2d expected =
        Model::kModelId == OpenCVFisheyeModel::kModelId
            ? UpstreamOpenCVFisheye(params, ray)
            : UpstreamThinPrismFisheye(params, ray);
    max_error = std::max(max_error, (pixel - expected).norm());
  }
  EXPECT_LT(max_error, 1e-9);
  // Exactly on the axis both give the principal point.
  const Eigen::Vector3d axis(0, 0, 2);
  Eigen::Vector2d pixel;
  ASSERT_TRUE(Model::ImageFromRay(params.data(), axis.data(), pixel.data()));
  EXPECT_EQ(pixel, Eigen::Vector2d(params[2], params[3]));
}

TYPED_TEST(KannalaBrandtTest, NotVisibleBeyondTheFold) {
  using Model = TypeParam;
  const std::vector<double> params = this->Params();
  const double theta_max = Model::FieldOfView(params.data()).theta_max;
  Eigen::Vector2d pixel;
  for (double phi = 0; phi < 2 * kPi; phi += 10 * kDeg) {
    const double limit = FieldLimitAt<Model>(params, phi);
    const Eigen::Vector3d inside = RayAt(limit - 1e-4, phi);
    EXPECT_TRUE(Model::ImageFromRay(params.data(), inside.data(), pixel.data()))
        << phi;
    for (double theta = limit + 1e-4; theta <= kPi; theta += 3 * kDeg) {
      const Eigen::Vector3d ray = RayAt(theta, phi);
      EXPECT_FALSE(Model::ImageFromRay(params.data(), ray.data(), pixel.data()))
          << theta / kDeg << " " << phi / kDeg;
    }
    // The pixel of a ray 1e-2 rad past the fold lies inside the fold circle
    // again and unprojects to the visible ray that owns it, about 2e-2 rad
    // before the fold.
    const Eigen::Vector3d past = RayAt(limit + 1e-2, phi);
    Model::ImageFromRay(params.data(), past.data(), pixel.data());
    Eigen::Vector3d back;
    if (Model::RayFromImage(params.data(), pixel.data(), back.data())) {
      EXPECT_GT(AngleBetween(back, past), 1e-3);
    }
  }
  // Pixels beyond the fold radius have no ray.
  const std::vector<double> k = RadialTerms<Model>(params);
  const double r_max = internal::KannalaBrandtRadius(k.data(), theta_max);
  for (double scale : {1.002, 1.1, 3.0}) {
    for (double phi = 0; phi < 2 * kPi; phi += 30 * kDeg) {
      const Eigen::Vector2d outside(
          params[2] + scale * r_max * params[0] * std::cos(phi),
          params[3] + scale * r_max * params[1] * std::sin(phi));
      Eigen::Vector3d ray;
      EXPECT_FALSE(
          Model::RayFromImage(params.data(), outside.data(), ray.data()))
          << scale << " " << phi / kDeg;
    }
  }
  const Eigen::Vector2d nan_pixel(std::nan(""), 3);
  Eigen::Vector3d ray;
  EXPECT_FALSE(
      Model::RayFromImage(params.data(), nan_pixel.data(), ray.data()));
}

TYPED_TEST(KannalaBrandtTest, AxisRays) {
  using Model = TypeParam;
  const std::vector<double> params = this->Params();
  Eigen::Vector2d pixel;
  const Eigen::Vector3d forward(0, 0, 1), backward(0, 0, -1), zero(0, 0, 0);
  ASSERT_TRUE(Model::ImageFromRay(params.data(), forward.data(), pixel.data()));
  EXPECT_EQ(pixel, Eigen::Vector2d(params[2], params[3]));
  EXPECT_FALSE(
      Model::ImageFromRay(params.data(), backward.data(), pixel.data()));
  EXPECT_TRUE(pixel.allFinite());
  EXPECT_FALSE(Model::ImageFromRay(params.data(), zero.data(), pixel.data()));
  Eigen::Vector3d ray;
  const Eigen::Vector2d centre(params[2], params[3]);
  ASSERT_TRUE(Model::RayFromImage(params.data(), centre.data(), ray.data()));
  EXPECT_EQ(ray, forward);
  // Continuous across the series used near the axis (theta < 1e-4 / 1e-6).
  for (double theta : {1e-12, 1e-8, 0.99e-6, 1.01e-6, 0.99e-4, 1.01e-4}) {
    const Eigen::Vector3d near_axis = RayAt(theta, 0.7);
    ASSERT_TRUE(
        Model::ImageFromRay(params.data(), near_axis.data(), pixel.data()));
    EXPECT_NEAR((pixel - centre).norm() / (theta * params[0]), 1, 1e-3);
    ASSERT_TRUE(Model::RayFromImage(params.data(), pixel.data(), ray.data()));
    EXPECT_LT(AngleBetween(ray, near_axis), 1e-15 + 1e-9 * theta) << theta;
  }
}

// Without a fold the field reaches the backward axis: rays 1e-3 rad from it
// are visible and round-trip; the axis itself (a whole circle of pixels) is
// not.
TEST(OpenCVFisheye, FoldFreeLensSeesAlmostEverything) {
  const std::vector<double>& params = kEquidistant;
  for (double theta : {170 * kDeg, 179 * kDeg, kPi - 1e-3}) {
    for (double phi = 0; phi < 2 * kPi; phi += 45 * kDeg) {
      const Eigen::Vector3d ray = RayAt(theta, phi);
      Eigen::Vector2d pixel;
      Eigen::Vector3d back;
      ASSERT_TRUE(OpenCVFisheyeModel::ImageFromRay(params.data(), ray.data(),
                                                   pixel.data()));
      EXPECT_NEAR((pixel - Eigen::Vector2d(320, 320)).norm(), 300 * theta,
                  1e-9);
      ASSERT_TRUE(OpenCVFisheyeModel::RayFromImage(params.data(), pixel.data(),
                                                   back.data()));
      EXPECT_LT(AngleBetween(ray, back), 1e-9);
    }
  }
  const Eigen::Vector3d backward(0, 0, -1);
  Eigen::Vector2d pixel;
  EXPECT_FALSE(OpenCVFisheyeModel::ImageFromRay(params.data(), backward.data(),
                                                pixel.data()));
  const Eigen::Vector2d on_circle(320 + 300 * kPi, 320);
  Eigen::Vector3d ray;
  EXPECT_FALSE(OpenCVFisheyeModel::RayFromImage(params.data(), on_circle.data(),
                                                ray.data()));
}

TEST(OpenCVFisheye, FieldInFrontOfImagePlaneMatchesScan) {
  test::ExpectFieldInFrontMatchesScan<OpenCVFisheyeModel>(kEquidistant);
  test::ExpectFieldInFrontMatchesScan<OpenCVFisheyeModel>(kFisheye);
  // A lens that folds at 85°: no pixel of any image sees a ray behind it.
  const std::vector<double> folds_early = {300, 300, 320, 320,
                                           -0.15, 0, 0, 0};
  ASSERT_LT(OpenCVFisheyeModel::FieldOfView(folds_early.data()).theta_max,
            kPi / 2);
  EXPECT_TRUE(OpenCVFisheyeModel::FieldInFrontOfImagePlane(folds_early.data(),
                                                           4000, 4000));
  EXPECT_FALSE(
      OpenCVFisheyeModel::FieldInFrontOfImagePlane(kEquidistant.data(), 0, 0));
}

TEST(ThinPrismFisheye, FieldInFrontOfImagePlaneMatchesScan) {
  test::ExpectFieldInFrontMatchesScan<ThinPrismFisheyeModel>(kThinPrism);
}

TEST(OpenCVFisheye, CheckParamsReportsFoldInsideImageCircle) {
  EXPECT_EQ(OpenCVFisheyeModel::CheckParams(kFisheye, 640, 640), "");
  EXPECT_EQ(OpenCVFisheyeModel::CheckParams(kFisheye, 0, 0), "");
  EXPECT_EQ(OpenCVFisheyeModel::CheckParams(kEquidistant, 4000, 4000), "");
  // The fold at 105.44° is r = 1.55667 f, 467.2 px along fy. A 1600 x 1088
  // image about (800.3, 544.2) holds a circle of 800.3 px (to its left
  // edge): the fold is inside it.
  std::vector<double> wide = kFisheye;
  wide[2] = 800.3;
  wide[3] = 544.2;
  const std::string message = OpenCVFisheyeModel::CheckParams(wide, 1600, 1088);
  EXPECT_THAT(message, HasSubstr("OPENCV_FISHEYE: projection folds at 105.4° "
                                 "(r = 467.2 px), inside the image circle of "
                                 "the 1600x1088 image (radius 800.3 px about "
                                 "the principal point (800.3, 544.2))"));
  // A 660 x 660 image about (320.3, 320.2): its corners (481 px away) lie
  // past the fold, its circle (339.8 px) does not. A fisheye's pixels end at
  // its circle, so the fold leaves every one of them its ray.
  EXPECT_EQ(OpenCVFisheyeModel::CheckParams(kFisheye, 660, 660), "");
  // A circle cropped by the top and bottom edges, as on 8-lens cameras: the
  // fold at 1.55667 * 450 = 700.5 px lies beyond the half height (544 px)
  // but inside the circle that reaches the left and right edges (800 px).
  std::vector<double> cropped = kFisheye;
  cropped[0] = cropped[1] = 450;
  cropped[2] = 800;
  cropped[3] = 544;
  EXPECT_THAT(OpenCVFisheyeModel::CheckParams(cropped, 1600, 1088),
              HasSubstr("(r = 700.5 px), inside the image circle"));
  // The same lens on a 1000 x 1000 image: circle 500 px, corners 707 px.
  cropped[2] = cropped[3] = 500;
  EXPECT_EQ(OpenCVFisheyeModel::CheckParams(cropped, 1000, 1000), "");

  EXPECT_THAT(OpenCVFisheyeModel::CheckParams({300, 300, 320, 320}, 0, 0),
              HasSubstr("expected 8 params"));
  std::vector<double> bad = kFisheye;
  bad[6] = std::nan("");
  EXPECT_THAT(OpenCVFisheyeModel::CheckParams(bad, 0, 0), HasSubstr("k3=nan"));
  bad = kFisheye;
  bad[1] = -1;
  EXPECT_THAT(OpenCVFisheyeModel::CheckParams(bad, 0, 0), HasSubstr("fy=-1"));
}

TEST(ThinPrismFisheye, CheckParamsReportsFoldInsideImageCircle) {
  EXPECT_EQ(ThinPrismFisheyeModel::CheckParams(kThinPrism, 640, 640), "");
  // Corners past the fold, the circle (339.8 px) inside it.
  EXPECT_EQ(ThinPrismFisheyeModel::CheckParams(kThinPrism, 660, 660), "");
  EXPECT_EQ(ThinPrismFisheyeModel::CheckParams(kThinPrism, 0, 0), "");
  const std::string message =
      ThinPrismFisheyeModel::CheckParams(kThinPrism, 1600, 1088);
  // The prism terms move the fold off 105.4° by less than a tenth of a degree.
  EXPECT_THAT(message,
              HasSubstr("THIN_PRISM_FISHEYE: projection folds at 105."));
  EXPECT_THAT(message, HasSubstr("inside the image circle of the 1600x1088 "
                                 "image (radius 1279.7 px about the "
                                 "principal point (320.3, 320.2)): at pixel"));
  EXPECT_THAT(ThinPrismFisheyeModel::CheckParams(kFisheye, 0, 0),
              HasSubstr("expected 12 params"));
  std::vector<double> bad = kThinPrism;
  bad[10] = INFINITY;
  EXPECT_THAT(ThinPrismFisheyeModel::CheckParams(bad, 0, 0),
              HasSubstr("sx1=inf"));
}

TEST(ThinPrismFisheye, DistortionJacobianMatchesCentralDifferences) {
  const double* extra = kThinPrism.data() + 4;
  for (const Eigen::Vector2d& ab :
       {Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(-1.2, 0.9),
        Eigen::Vector2d(0, 1.7)}) {
    double ad, bd, jacobian[4];
    internal::ThinPrismDistortion(extra, ab.x(), ab.y(), &ad, &bd, jacobian);
    const auto distort = [&](const std::vector<double>& x) {
      Eigen::VectorXd out(2);
      internal::ThinPrismDistortion(extra, x[0], x[1], &out[0], &out[1]);
      return out;
    };
    const Eigen::MatrixXd numeric =
        test::CentralDifferences(distort, {ab.x(), ab.y()}, 2);
    const Eigen::Matrix2d analytic =
        Eigen::Map<const Eigen::Matrix<double, 2, 2, Eigen::RowMajor>>(
            jacobian);
    EXPECT_LT((analytic - numeric).norm(), 1e-9) << ab.transpose();
  }
}

// Autodiff through both directions (Newton on values plus one step in Jets)
// against central differences, in front, beyond 90° and on the axis.
TYPED_TEST(KannalaBrandtTest, AutodiffMatchesCentralDifferences) {
  using Model = TypeParam;
  constexpr int N = Model::kNumParams;
  const std::vector<double> params = this->Params();
  // Away from the axis the distortion terms (1e-4 to 1e-2) need steps far
  // below the default 1e-4, as unprojection turns strongly non-linear in them
  // towards the fold; near the axis they hardly matter and a small step would
  // only measure rounding.
  std::vector<double> far_steps(N, 1e-6);
  for (int i = 0; i < 4; ++i) far_steps[i] = 1e-3;
  for (const Eigen::Vector3d& ray :
       {RayAt(0, 0), RayAt(1e-7, 0.3), RayAt(30 * kDeg, 1.1),
        RayAt(95 * kDeg, -2.0), RayAt(100 * kDeg, 2.9)}) {
    SCOPED_TRACE(::testing::Message() << "ray " << ray.transpose());
    const std::vector<double> steps =
        ray.z() > 0.99 ? std::vector<double>() : far_steps;
    test::ExpectAutodiffMatchesCentralDifferences<Model>(params, ray, steps);
  }
}

TEST(OpenCVFisheye, PixelToAngleIsOnePixelNearTheAxis) {
  const Eigen::Vector2d a(319.8, 320.2), b(320.8, 320.2);
  Eigen::Vector3d ray_a, ray_b;
  ASSERT_TRUE(OpenCVFisheyeModel::RayFromImage(kFisheye.data(), a.data(),
                                               ray_a.data()));
  ASSERT_TRUE(OpenCVFisheyeModel::RayFromImage(kFisheye.data(), b.data(),
                                               ray_b.data()));
  EXPECT_NEAR(AngleBetween(ray_a, ray_b) /
                  OpenCVFisheyeModel::PixelToAngle(kFisheye.data()),
              1, 1e-3);
}

}  // namespace
}  // namespace sphera
