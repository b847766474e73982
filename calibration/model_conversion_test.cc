#include "calibration/model_conversion.h"

#include <cmath>

#include <gtest/gtest.h>

#include "calibration/lens_projections.h"
#include "camera_models/registry.h"

namespace sphera {
namespace {

constexpr double kPi = 3.14159265358979323846;

ImageFromRayFunction ModelProjection(ModelId id, std::vector<double> params) {
  return [id, params](const Eigen::Vector3d& ray, Eigen::Vector2d* pixel) {
    return ImageFromRay(static_cast<int>(id), params, ray, pixel);
  };
}

TEST(SampleLens, ProjectionStopsAtTheFrameAndCoversTheField) {
  // An equidistant 1000x1000 lens, f = 250 px/rad: the frame's inscribed
  // circle (radius 500 px) is at 2 rad, the corners at 2.83 rad.
  const std::vector<double> params = {250, 250, 500, 500, 0, 0, 0, 0};
  const std::vector<RayPixelSample> samples = SampleLensByProjection(
      ModelProjection(ModelId::kOpenCVFisheye, params), 1000, 1000);
  ASSERT_GT(samples.size(), 1000u);
  double max_angle = 0;
  for (const RayPixelSample& sample : samples) {
    EXPECT_NEAR(sample.ray_in_cam.norm(), 1, 1e-12);
    EXPECT_GE(sample.pixel.x(), 0);
    EXPECT_LE(sample.pixel.x(), 1000);
    EXPECT_GE(sample.pixel.y(), 0);
    EXPECT_LE(sample.pixel.y(), 1000);
    max_angle = std::max(max_angle, std::atan2(sample.ray_in_cam.head<2>().norm(),
                                               sample.ray_in_cam.z()));
  }
  // Towards the corners the walk reaches 2.83 rad (162°), two-degree steps.
  EXPECT_GT(max_angle, 2.75);
  EXPECT_LT(max_angle, 2.0 * std::sqrt(2.0) + 1e-9);
}

TEST(SampleLens, ProjectionStopsWhereTheLensFolds) {
  // Radial-tangential with k1 < 0 folds at r² = -1 / (3 k1) = 1/3 on the
  // normalised plane (r = 0.577, 30°): the samples stop there, well inside
  // the frame.
  const std::vector<double> params = {500, 500, 1000, 1000, -1, 0, 0, 0};
  const std::vector<RayPixelSample> samples = SampleLensByProjection(
      ModelProjection(ModelId::kOpenCV, params), 2000, 2000);
  double max_angle = 0;
  for (const RayPixelSample& sample : samples) {
    max_angle = std::max(max_angle, std::atan2(sample.ray_in_cam.head<2>().norm(),
                                               sample.ray_in_cam.z()));
  }
  EXPECT_NEAR(max_angle, std::atan(std::sqrt(1.0 / 3.0)), 2.5 * kPi / 180);
}

TEST(SampleLens, UnprojectionMatchesProjection) {
  const std::vector<double> params = {300, 310, 640.5, 480.5, 0.1, -0.02,
                                      0.003, -0.0005};
  const int id = static_cast<int>(ModelId::kOpenCVFisheye);
  const std::vector<RayPixelSample> samples = SampleLensByUnprojection(
      [&](const Eigen::Vector2d& pixel, Eigen::Vector3d* ray) {
        return RayFromImage(id, params, pixel, ray);
      },
      Eigen::Vector2d(640.5, 480.5), 1280, 960);
  ASSERT_GT(samples.size(), 1000u);
  for (const RayPixelSample& sample : samples) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(ImageFromRay(id, params, sample.ray_in_cam, &pixel));
    EXPECT_NEAR((pixel - sample.pixel).norm(), 0, 1e-6);
  }
}

TEST(FitModel, RecoversTheSameModelExactly) {
  const std::vector<double> params = {320, 318, 641.3, 479.1, 0.01, -0.002,
                                      0.0003, -0.00002};
  const std::vector<RayPixelSample> samples = SampleLensByProjection(
      ModelProjection(ModelId::kOpenCVFisheye, params), 1280, 960);
  const ModelConversion fit = FitModelToSamples(
      static_cast<int>(ModelId::kOpenCVFisheye), samples, 1280, 960);
  EXPECT_EQ(fit.model_name, "OPENCV_FISHEYE");
  EXPECT_TRUE(fit.check_message.empty()) << fit.check_message;
  EXPECT_EQ(fit.errors.num_not_visible, 0);
  EXPECT_LT(fit.errors.max_error_px, 1e-6);
  for (size_t i = 0; i < params.size(); ++i) {
    EXPECT_NEAR(fit.params[i], params[i], 1e-6 * std::max(1.0, std::abs(params[i])))
        << i;
  }
}

TEST(FitModel, UnifiedOmniFromDoubleSphereBeyond180Degrees) {
  // A 1024x1024 double sphere lens that sees 195° inside the frame; Mei's
  // model describes it to a fraction of a pixel (Usenko et al. 2018, Table
  // 1), from a start that is a factor 2 off in focal length.
  const std::vector<double> params = {350, 350, 512.5, 512.5, -0.2, 0.6};
  const std::vector<RayPixelSample> samples = SampleLensByProjection(
      ModelProjection(ModelId::kDoubleSphere, params), 1024, 1024);
  const ModelConversion fit = FitModelToSamples(
      static_cast<int>(ModelId::kUnifiedOmni), samples, 1024, 1024);
  EXPECT_GT(fit.errors.max_angle_deg, 95);
  EXPECT_EQ(fit.errors.num_not_visible, 0);
  EXPECT_LT(fit.errors.max_error_px, 1.0);
  EXPECT_LT(fit.errors.median_error_px, 0.3);
  EXPECT_NEAR(fit.params[2], 512.5, 0.1);
}

TEST(FitModel, OCamFromKannalaBrandtOpensTheFieldBeyond90Degrees) {
  // OCAM starts as a pinhole that sees nothing beyond 90°; the staged fit
  // has to open it to the lens's 100° half field (the frame's corners).
  const std::vector<double> params = {400, 400, 500.5, 500.5, 0.02, -0.005,
                                      0, 0};
  const std::vector<RayPixelSample> samples = SampleLensByProjection(
      ModelProjection(ModelId::kOpenCVFisheye, params), 1001, 1001);
  const ModelConversion fit = FitModelToSamples(
      static_cast<int>(ModelId::kOCam), samples, 1001, 1001);
  EXPECT_GT(fit.errors.max_angle_deg, 95);
  EXPECT_EQ(fit.errors.num_not_visible, 0);
  // A polynomial of degree 4 in the sensor radius bends less than KB does
  // towards the corners: a few pixels there, a fraction of one inside.
  EXPECT_LT(fit.errors.max_error_px, 3.0);
  EXPECT_LT(fit.errors.median_error_px, 0.3);
  EXPECT_NEAR(fit.params[0], 500.5, 0.1);
  EXPECT_NEAR(fit.params[1], 500.5, 0.1);
}

TEST(FitModel, NearestModelOfAFovLensIsFitted) {
  GenericLens lens;
  lens.distortion = LensDistortion::kFov;
  lens.distortion_coeffs = {0.9};
  lens.fx = lens.fy = 400;
  lens.cx = 376.5;
  lens.cy = 240.5;
  const std::vector<RayPixelSample> samples = SampleLensByProjection(
      [&lens](const Eigen::Vector3d& ray, Eigen::Vector2d* pixel) {
        return lens.ImageFromRay(ray, pixel);
      },
      752, 480);
  const ModelConversion fit = FitNearestModel(samples, 752, 480);
  EXPECT_GE(fit.model_id, 0);
  EXPECT_EQ(fit.errors.num_not_visible, 0);
  EXPECT_LT(fit.errors.max_error_px, 0.5);
  // Every candidate is no better than the one chosen.
  for (const ModelId id : {ModelId::kOpenCVFisheye, ModelId::kEUCM}) {
    const ModelConversion other =
        FitModelToSamples(static_cast<int>(id), samples, 752, 480);
    EXPECT_GE(other.errors.max_error_px, fit.errors.max_error_px - 1e-12);
  }
}

TEST(FitModel, RefusesEquirectangularAndTooFewSamples) {
  const std::vector<RayPixelSample> few(3);
  EXPECT_THROW(FitModelToSamples(static_cast<int>(ModelId::kEquirectangular),
                                 few, 100, 50),
               std::invalid_argument);
  EXPECT_THROW(
      FitModelToSamples(static_cast<int>(ModelId::kOpenCV), few, 100, 50),
      std::invalid_argument);
}

TEST(ModelErrors, CountsRaysTheModelDoesNotSee) {
  std::vector<RayPixelSample> samples(2);
  samples[0].ray_in_cam = Eigen::Vector3d(0, 0, 1);
  samples[0].pixel = Eigen::Vector2d(50, 50);
  samples[1].ray_in_cam = Eigen::Vector3d(0, 0, -1);
  const ModelFitErrors errors = ModelErrors(
      static_cast<int>(ModelId::kPinhole), {100, 100, 50, 53}, samples);
  EXPECT_EQ(errors.num_samples, 2);
  EXPECT_EQ(errors.num_not_visible, 1);
  EXPECT_NEAR(errors.max_error_px, 3, 1e-12);
  EXPECT_NEAR(errors.max_angle_deg, 180, 1e-9);
}

}  // namespace
}  // namespace sphera
