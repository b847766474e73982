#include "colmap_ext/image/flat_field.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace colmap {
namespace {

const ImageCircle kCircle{101.5, 95.0, 90.0};

// A lens image: random smooth texture inside the circle, darkened by
// FALLOFF (the renderer's vignetting V = 1 - 0.7 rho^2 + 0.35 rho^4 by
// default), black outside.
cv::Mat LensImage(int seed, const RadialFalloff& falloff) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(60, 200);
  cv::Mat coarse(26, 26, CV_64F);
  for (int y = 0; y < coarse.rows; ++y) {
    for (int x = 0; x < coarse.cols; ++x) coarse.at<double>(y, x) = uniform(rng);
  }
  cv::Mat texture;
  cv::resize(coarse, texture, cv::Size(208, 192), 0, 0, cv::INTER_CUBIC);
  cv::Mat image(192, 208, CV_8UC3, cv::Scalar(0, 0, 0));
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const double rho = std::hypot(x + 0.5 - kCircle.cx, y + 0.5 - kCircle.cy) /
                         kCircle.r;
      if (rho >= 1) continue;
      const double value = texture.at<double>(y, x) * falloff.Gain(rho);
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uint8_t>(value),
                                            cv::saturate_cast<uint8_t>(0.9 * value),
                                            cv::saturate_cast<uint8_t>(value));
    }
  }
  return image;
}

RadialFalloff RenderersVignetting() {
  RadialFalloff falloff;
  falloff.a = -0.7;
  falloff.b = 0.35;
  return falloff;
}

TEST(FlatField, RecoversTheFalloffOfALensFromItsImages) {
  const RadialFalloff truth = RenderersVignetting();
  RadialFalloffEstimator estimator(kCircle, 10);
  for (int seed = 0; seed < 12; ++seed) estimator.Add(LensImage(seed, truth));
  EXPECT_EQ(estimator.NumImages(), 12);
  std::string why;
  const RadialFalloff fitted = estimator.Fit(3, 0.03, &why);
  ASSERT_FALSE(fitted.IsIdentity()) << why;
  for (const double rho : {0.2, 0.5, 0.8, 0.95}) {
    EXPECT_NEAR(fitted.Gain(rho), truth.Gain(rho), 0.03) << rho;
  }
  // Divided out: the images' profile is flat again.
  cv::Mat image = LensImage(99, truth);
  DivideByFalloff(kCircle, fitted, &image);
  RadialFalloffEstimator flat(kCircle, 10);
  for (int seed = 20; seed < 32; ++seed) {
    cv::Mat corrected = LensImage(seed, truth);
    DivideByFalloff(kCircle, fitted, &corrected);
    flat.Add(corrected);
  }
  EXPECT_TRUE(flat.Fit(3, 0.03, &why).IsIdentity());
  // Outside the circle nothing changes.
  EXPECT_EQ(image.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
}

TEST(FlatField, ImagesWithoutFalloffAreLeftAlone) {
  RadialFalloffEstimator estimator(kCircle, 10);
  for (int seed = 0; seed < 12; ++seed) {
    estimator.Add(LensImage(seed, RadialFalloff()));
  }
  std::string why;
  EXPECT_TRUE(estimator.Fit(3, 0.03, &why).IsIdentity());
  EXPECT_FALSE(why.empty());
  cv::Mat image = LensImage(0, RadialFalloff());
  const cv::Mat before = image.clone();
  DivideByFalloff(kCircle, estimator.Fit(), &image);
  EXPECT_EQ(cv::norm(image, before, cv::NORM_INF), 0);
}

TEST(FlatField, TooFewImagesOrABrighterRimAreNoFalloff) {
  RadialFalloffEstimator few(kCircle, 10);
  few.Add(LensImage(0, RenderersVignetting()));
  std::string why;
  EXPECT_TRUE(few.Fit(3, 0.03, &why).IsIdentity());
  EXPECT_NE(why.find("1 image(s)"), std::string::npos) << why;

  RadialFalloff brighter;
  brighter.a = 0.3;
  RadialFalloffEstimator rim(kCircle, 10);
  for (int seed = 0; seed < 6; ++seed) rim.Add(LensImage(seed, brighter));
  EXPECT_TRUE(rim.Fit(3, 0.03, &why).IsIdentity());
  EXPECT_NE(why.find("not a lens's"), std::string::npos) << why;

  // A black image says nothing.
  RadialFalloffEstimator black(kCircle, 10);
  black.Add(cv::Mat(192, 208, CV_8UC3, cv::Scalar(0, 0, 0)));
  EXPECT_EQ(black.NumImages(), 0);
}

}  // namespace
}  // namespace colmap
