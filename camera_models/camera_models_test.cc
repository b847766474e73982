// Properties shared by all models: round trips over the whole field of view,
// autodiff Jacobians against central differences, visibility and pixel domain.
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/autodiff_cost_function.h>
#include <gtest/gtest.h>

#include "camera_models/double_sphere.h"
#include "camera_models/equirectangular.h"
#include "camera_models/eucm.h"
#include "camera_models/model_test_util.h"
#include "camera_models/perspective.h"
#include "camera_models/unified_omni.h"

namespace sphera {
namespace {

constexpr double kPi = internal::kPi;
constexpr double kDeg = kPi / 180;

using test::AngleBetween;
using test::CentralDifferences;
using test::ExpectJacobianNear;
using test::ImageFromRayFunctor;
using test::RayAt;
using test::RayFromImageFunctor;

// Normalized radius of the projection of a ray at polar angle theta along +x.
template <typename Model>
double NormalizedRadiusAt(const std::vector<double>& params, double theta) {
  const Eigen::Vector3d ray = RayAt(theta, 0);
  Eigen::Vector2d pixel;
  Model::ImageFromRay(params.data(), ray.data(), pixel.data());
  return (pixel.x() - params[2]) / params[0];
}

// Per-model test configuration.
//   Params():        realistic parameters.
//   Width/Height():  image size; the pixel grid spans [0, W] x [0, H].
//   MaxRayAngle():   polar angle from +z up to which rays are round-tripped.
//   InvisibleAngle(): a polar angle outside the field of view (< 0: none).
//   InPixelDomain(): pixels of the grid that must round-trip.
//   OutsidePixels(): pixels that RayFromImage must reject.
//   JacobianSafe():  rays away from the model's singularities.
template <typename Model>
struct TestCamera;

template <>
struct TestCamera<PinholeModel> {
  static std::vector<double> Params() { return {500.5, 498.2, 640.3, 480.7}; }
  static int Width() { return 1280; }
  static int Height() { return 960; }
  static double MaxRayAngle() { return 80 * kDeg; }
  static double InvisibleAngle() { return 90 * kDeg + 1e-9; }
  static bool InPixelDomain(const Eigen::Vector2d&) { return true; }
  static std::vector<Eigen::Vector2d> OutsidePixels() { return {}; }
  static bool JacobianSafe(const Eigen::Vector3d&) { return true; }
};

template <>
struct TestCamera<OpenCVModel> {
  static std::vector<double> Params() {
    return {500.5, 498.2, 640.3, 480.7, -0.05, 0.01, 3e-4, -2e-4};
  }
  static int Width() { return 1280; }
  static int Height() { return 960; }
  // The image corners are 58 deg off axis.
  static double MaxRayAngle() { return 60 * kDeg; }
  static double InvisibleAngle() { return 90 * kDeg + 1e-9; }
  static bool InPixelDomain(const Eigen::Vector2d&) { return true; }
  static std::vector<Eigen::Vector2d> OutsidePixels() { return {}; }
  static bool JacobianSafe(const Eigen::Vector3d&) { return true; }
};

template <>
struct TestCamera<EUCMModel> {
  static std::vector<double> Params() {
    return {401.2, 399.8, 640.5, 480.5, 0.6, 1.1};
  }
  static int Width() { return 1280; }
  static int Height() { return 960; }
  // Boundary z = -w d with w = (1 - alpha) / alpha: z / rho = -sqrt(beta w² /
  // (1 - w²)).
  static double BoundaryAngle() {
    const double alpha = Params()[4], beta = Params()[5];
    const double w = (1 - alpha) / alpha;
    return kPi / 2 + std::atan(std::sqrt(beta * w * w / (1 - w * w)));
  }
  static double MaxRayAngle() { return BoundaryAngle() - 1e-3; }
  static double InvisibleAngle() { return BoundaryAngle() + 1e-3; }
  static double MaxRadius2() {
    const double alpha = Params()[4], beta = Params()[5];
    return 1 / (beta * (2 * alpha - 1));
  }
  static bool InPixelDomain(const Eigen::Vector2d& pixel) {
    const auto p = Params();
    const double mx = (pixel.x() - p[2]) / p[0], my = (pixel.y() - p[3]) / p[1];
    return mx * mx + my * my <= 0.98 * 0.98 * MaxRadius2();
  }
  static std::vector<Eigen::Vector2d> OutsidePixels() {
    const auto p = Params();
    const double r = std::sqrt(MaxRadius2()) * 1.01;
    return {{p[2] + r * p[0], p[3]},
            {p[2], p[3] - r * p[1]},
            {p[2] - 0.8 * r * p[0], p[3] + 0.8 * r * p[1]}};
  }
  static bool JacobianSafe(const Eigen::Vector3d&) { return true; }
};

template <>
struct TestCamera<DoubleSphereModel> {
  static std::vector<double> Params() {
    return {351.7, 350.9, 640.2, 480.9, -0.2, 0.6};
  }
  static int Width() { return 1280; }
  static int Height() { return 960; }
  // Unit ray on the boundary xi + z = -w1 sqrt(1 + 2 xi z + xi²), solved for z.
  static double BoundaryAngle() {
    const double xi = Params()[4], alpha = Params()[5];
    const double w1 = (1 - alpha) / alpha;
    const double z = -xi * (1 - w1 * w1) -
                     w1 * std::sqrt(1 - xi * xi + xi * xi * w1 * w1);
    return std::atan2(std::sqrt(1 - z * z), z);
  }
  static double MaxRayAngle() { return BoundaryAngle() - 1e-3; }
  static double InvisibleAngle() { return BoundaryAngle() + 1e-3; }
  static double MaxRadius2() { return 1 / (2 * Params()[5] - 1); }
  static bool InPixelDomain(const Eigen::Vector2d& pixel) {
    const auto p = Params();
    const double mx = (pixel.x() - p[2]) / p[0], my = (pixel.y() - p[3]) / p[1];
    return mx * mx + my * my <= 0.98 * 0.98 * MaxRadius2();
  }
  static std::vector<Eigen::Vector2d> OutsidePixels() {
    const auto p = Params();
    const double r = std::sqrt(MaxRadius2()) * 1.01;
    return {{p[2] + r * p[0], p[3]}, {p[2], p[3] + r * p[1]}};
  }
  static bool JacobianSafe(const Eigen::Vector3d&) { return true; }
};

// 190 deg fisheye whose 95 deg image circle fits the image.
template <>
struct TestCamera<UnifiedOmniModel> {
  static std::vector<double> Params() {
    return {330.4, 331.2, 640.6, 480.3, 1.05, -0.04, 0.008, 2e-4, -1e-4};
  }
  static int Width() { return 1280; }
  static int Height() { return 960; }
  static double MaxRayAngle() { return 95 * kDeg; }
  // xi > 1: visible iff sz > -1 / xi.
  static double InvisibleAngle() {
    return std::atan2(std::sqrt(1 - 1 / (1.05 * 1.05)), -1 / 1.05) + 1e-3;
  }
  static bool InPixelDomain(const Eigen::Vector2d& pixel) {
    const auto p = Params();
    const double radius = NormalizedRadiusAt<UnifiedOmniModel>(p, 95 * kDeg);
    const double mx = (pixel.x() - p[2]) / p[0], my = (pixel.y() - p[3]) / p[1];
    return std::hypot(mx, my) <= 0.97 * radius;
  }
  // Undistorted r² > 1 / (xi² - 1) = 9.76 lies beyond distorted radius 4.3.
  static std::vector<Eigen::Vector2d> OutsidePixels() {
    const auto p = Params();
    return {{p[2] + 5.5 * p[0], p[3]}, {p[2], p[3] - 6 * p[1]}};
  }
  static bool JacobianSafe(const Eigen::Vector3d&) { return true; }
};

template <>
struct TestCamera<EquirectangularModel> {
  static std::vector<double> Params() { return {2048, 1024}; }
  static int Width() { return 2048; }
  static int Height() { return 1024; }
  static double MaxRayAngle() { return kPi; }
  static double InvisibleAngle() { return -1; }
  static bool InPixelDomain(const Eigen::Vector2d&) { return true; }
  static std::vector<Eigen::Vector2d> OutsidePixels() {
    return {{-0.5, 100}, {2048.5, 100}, {100, -1e-3}, {100, 1025}};
  }
  // Away from the poles (+-y) and the +-180 deg seam (x = 0, z < 0).
  static bool JacobianSafe(const Eigen::Vector3d& ray) {
    return std::abs(ray.y()) < 0.9 && !(ray.z() < 0 && std::abs(ray.x()) < 0.2);
  }
};

template <typename Model>
class ModelTest : public ::testing::Test {};

using Models = ::testing::Types<PinholeModel, OpenCVModel, EUCMModel,
                                DoubleSphereModel, UnifiedOmniModel,
                                EquirectangularModel>;
TYPED_TEST_SUITE(ModelTest, Models);

TYPED_TEST(ModelTest, RayPixelRayRoundTripOverFieldOfView) {
  using Model = TypeParam;
  using S = TestCamera<Model>;
  const std::vector<double> params = S::Params();
  constexpr int kNumTheta = 181;
  constexpr int kNumPhi = 181;
  double max_error = 0;
  Eigen::Vector3d worst_ray = Eigen::Vector3d::Zero();
  int num_failed = 0;
  for (int i = 0; i < kNumTheta; ++i) {
    const double theta = S::MaxRayAngle() * i / (kNumTheta - 1);
    for (int j = 0; j < kNumPhi; ++j) {
      const double phi = -kPi + 2 * kPi * j / (kNumPhi - 1);
      const Eigen::Vector3d ray = RayAt(theta, phi);
      Eigen::Vector2d pixel;
      Eigen::Vector3d ray_back;
      if (!Model::ImageFromRay(params.data(), ray.data(), pixel.data()) ||
          !Model::RayFromImage(params.data(), pixel.data(), ray_back.data())) {
        ++num_failed;
        worst_ray = ray;
        continue;
      }
      EXPECT_NEAR(ray_back.norm(), 1, 1e-12);
      const double error = AngleBetween(ray, ray_back);
      if (!(error <= max_error)) {
        max_error = error;
        worst_ray = ray;
      }
    }
  }
  EXPECT_EQ(num_failed, 0) << "last failed ray " << worst_ray.transpose();
  EXPECT_LT(max_error, 1e-9) << "worst ray " << worst_ray.transpose();
}

TYPED_TEST(ModelTest, PixelRayPixelRoundTripOverDomain) {
  using Model = TypeParam;
  using S = TestCamera<Model>;
  const std::vector<double> params = S::Params();
  constexpr int kNumX = 257;
  constexpr int kNumY = 193;
  double max_error = 0;
  Eigen::Vector2d worst_pixel = Eigen::Vector2d::Zero();
  int num_tested = 0;
  int num_failed = 0;
  for (int i = 0; i < kNumX; ++i) {
    for (int j = 0; j < kNumY; ++j) {
      const Eigen::Vector2d pixel(S::Width() * double(i) / (kNumX - 1),
                                  S::Height() * double(j) / (kNumY - 1));
      if (!S::InPixelDomain(pixel)) continue;
      ++num_tested;
      Eigen::Vector3d ray;
      Eigen::Vector2d pixel_back;
      if (!Model::RayFromImage(params.data(), pixel.data(), ray.data()) ||
          !Model::ImageFromRay(params.data(), ray.data(), pixel_back.data())) {
        ++num_failed;
        worst_pixel = pixel;
        continue;
      }
      const double error = (pixel - pixel_back).norm();
      if (!(error <= max_error)) {
        max_error = error;
        worst_pixel = pixel;
      }
    }
  }
  EXPECT_GT(num_tested, kNumX * kNumY / 5);
  EXPECT_EQ(num_failed, 0) << "last failed pixel " << worst_pixel.transpose();
  EXPECT_LT(max_error, 1e-6) << "worst pixel " << worst_pixel.transpose();
}

TYPED_TEST(ModelTest, AutodiffJacobiansMatchCentralDifferences) {
  using Model = TypeParam;
  using S = TestCamera<Model>;
  constexpr int N = Model::kNumParams;
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic,
                                 Eigen::RowMajor>;
  const std::vector<double> params = S::Params();
  ceres::AutoDiffCostFunction<ImageFromRayFunctor<Model>, 2, 3, N> project(
      new ImageFromRayFunctor<Model>);
  ceres::AutoDiffCostFunction<RayFromImageFunctor<Model>, 3, 2, N> unproject(
      new RayFromImageFunctor<Model>);

  std::mt19937 rng(42);
  std::uniform_real_distribution<double> unit(0, 1);
  int num_tested = 0;
  while (num_tested < 40) {
    const double theta = (0.05 + 0.85 * unit(rng)) * S::MaxRayAngle();
    const Eigen::Vector3d ray = RayAt(theta, 2 * kPi * unit(rng));
    if (!S::JacobianSafe(ray)) continue;
    ++num_tested;

    // d pixel / d ray, d pixel / d params.
    Eigen::Vector2d pixel;
    RowMajor d_ray(2, 3), d_params(2, N);
    {
      const double* blocks[2] = {ray.data(), params.data()};
      double* jacobians[2] = {d_ray.data(), d_params.data()};
      ASSERT_TRUE(project.Evaluate(blocks, pixel.data(), jacobians));
    }
    auto project_ray = [&](const std::vector<double>& r) {
      Eigen::VectorXd p(2);
      EXPECT_TRUE(Model::ImageFromRay(params.data(), r.data(), p.data()));
      return p;
    };
    auto project_params = [&](const std::vector<double>& q) {
      Eigen::VectorXd p(2);
      EXPECT_TRUE(Model::ImageFromRay(q.data(), ray.data(), p.data()));
      return p;
    };
    ExpectJacobianNear(
        d_ray,
        CentralDifferences(project_ray, {ray.x(), ray.y(), ray.z()}, 2),
        "ImageFromRay d/dray");
    ExpectJacobianNear(d_params,
                       CentralDifferences(project_params, params, 2),
                       "ImageFromRay d/dparams");

    // d ray / d pixel, d ray / d params (exercises Newton on Jets).
    Eigen::Vector3d ray_back;
    RowMajor u_pixel(3, 2), u_params(3, N);
    {
      const double* blocks[2] = {pixel.data(), params.data()};
      double* jacobians[2] = {u_pixel.data(), u_params.data()};
      ASSERT_TRUE(unproject.Evaluate(blocks, ray_back.data(), jacobians));
    }
    auto unproject_pixel = [&](const std::vector<double>& p) {
      Eigen::VectorXd r(3);
      EXPECT_TRUE(Model::RayFromImage(params.data(), p.data(), r.data()));
      return r;
    };
    auto unproject_params = [&](const std::vector<double>& q) {
      Eigen::VectorXd r(3);
      EXPECT_TRUE(Model::RayFromImage(q.data(), pixel.data(), r.data()));
      return r;
    };
    ExpectJacobianNear(
        u_pixel,
        CentralDifferences(unproject_pixel, {pixel.x(), pixel.y()}, 3),
        "RayFromImage d/dpixel");
    ExpectJacobianNear(u_params,
                       CentralDifferences(unproject_params, params, 3),
                       "RayFromImage d/dparams");
  }
}

TYPED_TEST(ModelTest, RaysOutsideFieldOfViewAreNotVisible) {
  using Model = TypeParam;
  using S = TestCamera<Model>;
  const std::vector<double> params = S::Params();
  Eigen::Vector2d pixel;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  EXPECT_FALSE(Model::ImageFromRay(params.data(), zero.data(), pixel.data()));
  if (S::InvisibleAngle() < 0) return;
  for (double theta = S::InvisibleAngle(); theta <= kPi; theta += 2 * kDeg) {
    for (double phi = -kPi; phi < kPi; phi += 15 * kDeg) {
      const Eigen::Vector3d ray = RayAt(theta, phi);
      EXPECT_FALSE(Model::ImageFromRay(params.data(), ray.data(), pixel.data()))
          << "theta " << theta / kDeg << " deg, phi " << phi / kDeg << " deg";
    }
  }
}

TYPED_TEST(ModelTest, PixelsOutsideDomainAreRejected) {
  using Model = TypeParam;
  const std::vector<double> params = TestCamera<Model>::Params();
  for (const Eigen::Vector2d& pixel : TestCamera<Model>::OutsidePixels()) {
    Eigen::Vector3d ray;
    EXPECT_FALSE(Model::RayFromImage(params.data(), pixel.data(), ray.data()))
        << "pixel " << pixel.transpose();
  }
}

TYPED_TEST(ModelTest, CenterPixelIsOpticalAxisAndPixelToAngleMatches) {
  using Model = TypeParam;
  using S = TestCamera<Model>;
  const std::vector<double> params = S::Params();
  const Eigen::Vector3d axis(0, 0, 1);
  Eigen::Vector2d center;
  ASSERT_TRUE(Model::ImageFromRay(params.data(), axis.data(), center.data()));
  // One pixel step around the image of the optical axis.
  for (const Eigen::Vector2d& step :
       {Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 1)}) {
    const Eigen::Vector2d a = center - 0.5 * step, b = center + 0.5 * step;
    Eigen::Vector3d ray_a, ray_b;
    ASSERT_TRUE(Model::RayFromImage(params.data(), a.data(), ray_a.data()));
    ASSERT_TRUE(Model::RayFromImage(params.data(), b.data(), ray_b.data()));
    EXPECT_NEAR(AngleBetween(ray_a, ray_b) / Model::PixelToAngle(params.data()),
                1, 0.01);
  }
}

// The visible set must be exactly the polar-angle interval on which the
// (rotationally symmetric, undistorted) projection radius increases: beyond
// it the projection folds back (non-injective) or the denominator changes
// sign. This verifies the closed-form Omega of each model independently.
template <typename Model>
void ExpectFieldOfViewIsInjectivityLimit(const std::vector<double>& params) {
  SCOPED_TRACE(::testing::Message() << Model::kModelName << " params "
                                    << Eigen::Map<const Eigen::VectorXd>(
                                           params.data(), params.size())
                                           .transpose());
  constexpr double kStep = 1e-4;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double injective_until = kPi;
  double visible_until = kPi;
  double prev_u = -std::numeric_limits<double>::infinity();
  bool seen_invisible = false;
  for (double theta = 0; theta <= kPi - kStep; theta += kStep) {
    const Eigen::Vector3d ray = RayAt(theta, 0);
    Eigen::Vector2d pixel(nan, nan);
    const bool visible =
        Model::ImageFromRay(params.data(), ray.data(), pixel.data());
    const double u = (pixel.x() - params[2]) / params[0];
    if (injective_until == kPi && !(u > prev_u)) injective_until = theta;
    prev_u = u;
    if (!visible && !seen_invisible) {
      visible_until = theta;
      seen_invisible = true;
    }
    EXPECT_FALSE(seen_invisible && visible)
        << "visible set is not an interval at theta " << theta;
    if (visible && theta < visible_until - 1e-3) {
      Eigen::Vector3d ray_back;
      ASSERT_TRUE(
          Model::RayFromImage(params.data(), pixel.data(), ray_back.data()));
      ASSERT_LT(AngleBetween(ray, ray_back), 1e-9) << "theta " << theta;
    }
  }
  EXPECT_NEAR(visible_until, injective_until, 2.5 * kStep);
}

TEST(FieldOfView, EUCMVisibleSetIsInjectivityLimit) {
  for (const auto& [alpha, beta] : std::vector<std::pair<double, double>>{
           {0.0, 1.0}, {0.3, 1.0}, {0.5, 1.2}, {0.6, 1.1}, {0.8, 0.7},
           {0.7, 2.5}, {1.0, 1.0}}) {
    ExpectFieldOfViewIsInjectivityLimit<EUCMModel>(
        {400, 400, 640, 480, alpha, beta});
  }
}

TEST(EUCM, FieldInFrontOfImagePlaneMatchesScan) {
  // Rays with z = 0 land 1 / (alpha sqrt(beta)) from the axis: 477, 461 and
  // 522 px at f = 300.
  for (const auto& [alpha, beta] : std::vector<std::pair<double, double>>{
           {0.6, 1.1}, {0.62, 1.1}, {0.5, 1.32}}) {
    test::ExpectFieldInFrontMatchesScan<EUCMModel>(
        {300, 301, 320.3, 320.2, alpha, beta});
  }
  const std::vector<double> pinhole = {300, 300, 320, 320, 0.0, 1.0};
  EXPECT_TRUE(EUCMModel::FieldInFrontOfImagePlane(pinhole.data(), 4000, 4000));
}

TEST(FieldOfView, DoubleSphereVisibleSetIsInjectivityLimit) {
  for (const auto& [xi, alpha] : std::vector<std::pair<double, double>>{
           {-0.2, 0.6}, {0.0, 0.5}, {0.5, 0.3}, {0.9, 0.7}, {-0.5, 0.8},
           {0.3, 0.0}, {1.0, 0.55}}) {
    ExpectFieldOfViewIsInjectivityLimit<DoubleSphereModel>(
        {400, 400, 640, 480, xi, alpha});
  }
}

TEST(FieldOfView, UnifiedOmniVisibleSetIsInjectivityLimit) {
  for (const double xi : {0.0, 0.5, 0.95, 1.2, 2.0}) {
    ExpectFieldOfViewIsInjectivityLimit<UnifiedOmniModel>(
        {400, 400, 640, 480, xi, 0, 0, 0, 0});
  }
}

// A 190 deg lens: rays 95 deg off axis project inside the image and 100 deg
// rays still project (the model's field of view, not the lens, is the limit).
TEST(FieldOfView, UnifiedOmniCovers190DegreeFisheye) {
  const std::vector<double> params = TestCamera<UnifiedOmniModel>::Params();
  for (double phi = -kPi; phi < kPi; phi += 10 * kDeg) {
    const Eigen::Vector3d ray = RayAt(95 * kDeg, phi);
    Eigen::Vector2d pixel;
    ASSERT_TRUE(UnifiedOmniModel::ImageFromRay(params.data(), ray.data(),
                                               pixel.data()));
    EXPECT_GT(pixel.x(), 0);
    EXPECT_LT(pixel.x(), 1280);
    EXPECT_GT(pixel.y(), 0);
    EXPECT_LT(pixel.y(), 960);
  }
}

// With xi < 1 the field of view is sz > -xi: a 190 deg lens (xi = cos 95 deg
// would be its limit) rejects rays 100 deg off axis.
TEST(FieldOfView, UnifiedOmniSmallXiRejectsRaysBeyondLimit) {
  const double xi = -std::cos(97 * kDeg);
  const std::vector<double> params = {300, 300, 640, 480, xi, 0, 0, 0, 0};
  Eigen::Vector2d pixel;
  const Eigen::Vector3d inside = RayAt(95 * kDeg, 0.3);
  const Eigen::Vector3d outside = RayAt(100 * kDeg, 0.3);
  EXPECT_TRUE(UnifiedOmniModel::ImageFromRay(params.data(), inside.data(),
                                             pixel.data()));
  EXPECT_FALSE(UnifiedOmniModel::ImageFromRay(params.data(), outside.data(),
                                              pixel.data()));
}

TEST(Perspective, OpenCVDistortionMatchesColmapFormula) {
  const std::vector<double> params = {500, 490, 320, 240,
                                      -0.1, 0.02, 1e-3, -2e-3};
  const Eigen::Vector3d ray(0.3, -0.2, 1.0);
  const double u = 0.3, v = -0.2, r2 = u * u + v * v;
  const double radial = -0.1 * r2 + 0.02 * r2 * r2;
  const double du = u * radial + 2 * 1e-3 * u * v + -2e-3 * (r2 + 2 * u * u);
  const double dv = v * radial + 2 * -2e-3 * u * v + 1e-3 * (r2 + 2 * v * v);
  Eigen::Vector2d pixel;
  ASSERT_TRUE(OpenCVModel::ImageFromRay(params.data(), ray.data(), pixel.data()));
  EXPECT_NEAR(pixel.x(), 500 * (u + du) + 320, 1e-12);
  EXPECT_NEAR(pixel.y(), 490 * (v + dv) + 240, 1e-12);
}

TEST(Perspective, RaysBehindOrOnImagePlaneAreNotVisible) {
  const std::vector<double> params = {500, 500, 320, 240};
  Eigen::Vector2d pixel;
  for (const Eigen::Vector3d& ray :
       {Eigen::Vector3d(0.1, 0.2, 0.0), Eigen::Vector3d(0.1, 0.2, -1.0),
        Eigen::Vector3d(0.0, 0.0, -1.0)}) {
    EXPECT_FALSE(PinholeModel::ImageFromRay(params.data(), ray.data(),
                                            pixel.data()));
  }
}

}  // namespace
}  // namespace sphera
