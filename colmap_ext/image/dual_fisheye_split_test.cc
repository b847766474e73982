#include "colmap_ext/image/dual_fisheye_split.h"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace colmap {
namespace {

// Whether TEXT contains NEEDLE; says what TEXT is when not.
testing::AssertionResult Contains(const std::string& text,
                                  const std::string& needle) {
  if (text.find(needle) != std::string::npos) {
    return testing::AssertionSuccess();
  }
  return testing::AssertionFailure()
         << "\"" << text << "\" does not contain \"" << needle << "\"";
}

// Whether pixel (x, y) is inside CIRCLE by the stated rule, written out
// independently of ImageCircleMask.
bool Inside(int x, int y, const ImageCircle& circle) {
  const double dx = x + 0.5 - circle.cx;
  const double dy = y + 0.5 - circle.cy;
  const double dx_squared = dx * dx;
  const double dy_squared = dy * dy;
  return dx_squared + dy_squared <= circle.r * circle.r;
}

// A raw frame of two WIDTH x HEIGHT lens images: random texture in
// [min_value, 255] inside the circles, black (0) outside.
cv::Mat MakeRawFrame(int width,
                     int height,
                     int type,
                     const std::array<ImageCircle, 2>& circles,
                     int min_value = 20) {
  cv::Mat raw(height, 2 * width, type);
  const double max_value = CV_MAT_DEPTH(type) == CV_16U ? 65535 : 255;
  cv::theRNG().state = 7;
  cv::randu(raw, cv::Scalar::all(min_value), cv::Scalar::all(max_value + 1));
  for (int lens = 0; lens < 2; ++lens) {
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        if (!Inside(x, y, circles[lens])) {
          cv::Mat pixel = raw(cv::Rect(lens * width + x, y, 1, 1));
          pixel.setTo(cv::Scalar::all(0));
        }
      }
    }
  }
  return raw;
}

TEST(DualFisheyeSplit, CopiesPixelsExactlyAndBlacksOutTheSurround) {
  // Non-square lens images, circles not centred, 16-bit colour + alpha.
  const int width = 50;
  const int height = 44;
  const std::array<ImageCircle, 2> circles = {ImageCircle{24.3, 21.9, 19.7},
                                              ImageCircle{26.0, 22.0, 21.5}};
  for (const int type : {CV_8UC1, CV_8UC3, CV_16UC4}) {
    cv::Mat raw(height, 2 * width, type);
    cv::randu(raw, cv::Scalar::all(0), cv::Scalar::all(256));
    const std::array<LensImage, 2> lenses = SplitDualFisheye(raw, circles);
    for (int lens = 0; lens < 2; ++lens) {
      const cv::Mat& image = lenses[lens].image;
      const cv::Mat& mask = lenses[lens].mask;
      ASSERT_EQ(image.type(), type);
      ASSERT_EQ(image.size(), cv::Size(width, height));
      ASSERT_EQ(mask.type(), CV_8UC1);
      ASSERT_EQ(mask.size(), cv::Size(width, height));
      const cv::Mat region = raw(cv::Rect(lens * width, 0, width, height));
      for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
          const bool inside = Inside(x, y, circles[lens]);
          ASSERT_EQ(mask.at<uchar>(y, x), inside ? 255 : 0) << x << "," << y;
          const size_t pixel_bytes = image.elemSize();
          const uchar* got = image.ptr(y) + x * pixel_bytes;
          const uchar* original = region.ptr(y) + x * pixel_bytes;
          for (size_t b = 0; b < pixel_bytes; ++b) {
            ASSERT_EQ(got[b], inside ? original[b] : 0)
                << "lens " << lens << " pixel " << x << "," << y;
          }
        }
      }
    }
  }
}

TEST(DualFisheyeSplit, MaskFollowsThePixelCentreConvention) {
  // Centre on the centre of pixel (5, 5); the centres of (7, 5), (3, 5),
  // (5, 7), (5, 3) are exactly r away: inside (<=); one more pixel is not.
  const ImageCircle circle{5.5, 5.5, 2.0};
  const cv::Mat mask = ImageCircleMask(cv::Size(12, 10), circle);
  EXPECT_EQ(mask.at<uchar>(5, 7), 255);
  EXPECT_EQ(mask.at<uchar>(5, 3), 255);
  EXPECT_EQ(mask.at<uchar>(7, 5), 255);
  EXPECT_EQ(mask.at<uchar>(3, 5), 255);
  EXPECT_EQ(mask.at<uchar>(5, 8), 0);
  EXPECT_EQ(mask.at<uchar>(8, 5), 0);
  EXPECT_EQ(mask.at<uchar>(7, 7), 0);  // sqrt(8) > 2
  EXPECT_EQ(cv::countNonZero(mask), 13);

  // The upper-left corner of the image is (0, 0): a circle around (1, 1)
  // holds the 4 pixels that meet there.
  const cv::Mat corner =
      ImageCircleMask(cv::Size(4, 4), ImageCircle{1.0, 1.0, 0.71});
  EXPECT_EQ(cv::countNonZero(corner), 4);
  EXPECT_EQ(corner.at<uchar>(0, 0), 255);
  EXPECT_EQ(corner.at<uchar>(1, 1), 255);
  EXPECT_EQ(corner.at<uchar>(2, 2), 0);
  // Rows are y, columns x: a circle off the diagonal.
  const cv::Mat off_diagonal =
      ImageCircleMask(cv::Size(8, 4), ImageCircle{6.5, 1.5, 0.5});
  EXPECT_EQ(off_diagonal.at<uchar>(1, 6), 255);
  EXPECT_EQ(cv::countNonZero(off_diagonal), 1);
}

TEST(DualFisheyeSplit, DetectsADrawnCircleWithinOnePixel) {
  const int width = 200;
  const int height = 180;
  const std::array<ImageCircle, 2> circles = {ImageCircle{97.3, 88.6, 80.2},
                                              ImageCircle{103.8, 91.1, 85.45}};
  for (const int type : {CV_8UC3, CV_16UC1}) {
    cv::Mat raw = MakeRawFrame(
        width, height, type, circles, CV_MAT_DEPTH(type) == CV_16U ? 5000 : 20);
    cv::Mat lens0 = raw(cv::Rect(0, 0, width, height));
    // Dark scene content at the rim of lens 0 and bright specks in its
    // surround must not pull the circle.
    lens0(cv::Rect(10, 70, 40, 30)).setTo(cv::Scalar::all(0));
    for (const cv::Point speck : {cv::Point(3, 5),
                                  cv::Point(190, 170),
                                  cv::Point(195, 10),
                                  cv::Point(5, 175)}) {
      lens0.at<uchar>(speck.y, speck.x * static_cast<int>(lens0.elemSize())) =
          255;
    }
    for (int lens = 0; lens < 2; ++lens) {
      ImageCircle detected;
      const std::string error = DetectImageCircle(
          raw(cv::Rect(lens * width, 0, width, height)), 10, &detected);
      ASSERT_EQ(error, "") << "lens " << lens;
      EXPECT_NEAR(detected.cx, circles[lens].cx, 1.0) << "lens " << lens;
      EXPECT_NEAR(detected.cy, circles[lens].cy, 1.0) << "lens " << lens;
      EXPECT_NEAR(detected.r, circles[lens].r, 1.0) << "lens " << lens;
      if (lens == 1) {
        // A clean hard-edged disc: its mask comes back but for a pixel or
        // two on the rim (the centre is an estimate).
        const cv::Mat difference =
            ImageCircleMask(cv::Size(width, height), detected) !=
            ImageCircleMask(cv::Size(width, height), circles[lens]);
        EXPECT_LE(cv::countNonZero(difference), 2);
      }
    }
  }
}

TEST(DualFisheyeSplit, DetectsACircleThatTouchesTheEdges) {
  // The inscribed circle: its boundary points on the image's border are
  // left out, and a fit that overshoots by a fraction of a pixel is shrunk.
  const int size = 120;
  const ImageCircle circle{60, 60, 60};
  const cv::Mat raw = MakeRawFrame(size, size, CV_8UC1, {circle, circle});
  ImageCircle detected;
  ASSERT_EQ(DetectImageCircle(raw(cv::Rect(0, 0, size, size)), 10, &detected),
            "");
  EXPECT_NEAR(detected.cx, 60, 1.0);
  EXPECT_NEAR(detected.cy, 60, 1.0);
  EXPECT_NEAR(detected.r, 60, 1.0);
  const ImageCircle clamped =
      ClampDetectedImageCircle(detected, cv::Size(size, size));
  EXPECT_EQ(ImageCircleError(clamped, cv::Size(size, size)), "");
  EXPECT_NEAR(clamped.r, 60, 1.0);
}

TEST(DualFisheyeSplit, FindsNoCircleInBlackOrFullImages) {
  ImageCircle detected;
  EXPECT_TRUE(Contains(
      DetectImageCircle(cv::Mat::zeros(50, 50, CV_8UC1), 10, &detected),
      "no image circle found"));
  EXPECT_TRUE(Contains(
      DetectImageCircle(
          cv::Mat(50, 50, CV_8UC3, cv::Scalar::all(90)), 10, &detected),
      "no image circle found"));
  // A bright band across the image: its edges are lines, not a circle.
  cv::Mat band = cv::Mat::zeros(60, 60, CV_8UC1);
  band.rowRange(20, 40).setTo(200);
  EXPECT_TRUE(Contains(DetectImageCircle(band, 10, &detected),
                       "no image circle found"));
}

TEST(DualFisheyeSplit, RefusesAFrameThatIsNotBlackOutsideTheCircles) {
  const int size = 64;
  const std::array<ImageCircle, 2> circles = {ImageCircle{32, 32, 30},
                                              ImageCircle{32, 32, 30}};
  cv::Mat raw = MakeRawFrame(size, size, CV_8UC3, circles);
  EXPECT_EQ(DualFisheyeFrameError(raw, circles, 10), "");
  EXPECT_EQ(BrightFractionOutsideCircles(raw, circles, 10), 0.0);

  // Noise at or below the black level and a few bright specks pass.
  cv::Mat noisy = raw.clone();
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < 2 * size; ++x) {
      cv::Vec3b& pixel = noisy.at<cv::Vec3b>(y, x);
      if (pixel == cv::Vec3b(0, 0, 0)) {
        pixel = cv::Vec3b((x + y) % 11, 3, 10);
      }
    }
  }
  noisy.at<cv::Vec3b>(0, 0) = cv::Vec3b(0, 0, 200);
  noisy.at<cv::Vec3b>(63, 127) = cv::Vec3b(11, 0, 0);
  EXPECT_EQ(DualFisheyeFrameError(noisy, circles, 10), "");
  EXPECT_GT(BrightFractionOutsideCircles(noisy, circles, 10), 0.0);

  // A normal photo (texture everywhere) is refused, and so is a frame
  // whose surround is brighter than the black level.
  cv::Mat photo(size, 2 * size, CV_8UC3);
  cv::randu(photo, cv::Scalar::all(0), cv::Scalar::all(256));
  EXPECT_TRUE(Contains(DualFisheyeFrameError(photo, circles, 10),
                       "not a dual-fisheye frame"));
  EXPECT_TRUE(Contains(DualFisheyeFrameError(noisy, circles, 5),
                       "not a dual-fisheye frame"));
  // In 16-bit images the black level is scaled by 257.
  cv::Mat raw16;
  noisy.convertTo(raw16, CV_16U, 257);
  EXPECT_EQ(DualFisheyeFrameError(raw16, circles, 10), "");
}

TEST(DualFisheyeSplit, RefusesAnOddWidth) {
  const cv::Mat raw(40, 81, CV_8UC3, cv::Scalar::all(0));
  EXPECT_TRUE(Contains(DualFisheyeLayoutError(raw), "odd width 81"));
  const std::array<ImageCircle, 2> circles = {ImageCircle{20, 20, 10},
                                              ImageCircle{20, 20, 10}};
  EXPECT_TRUE(Contains(DualFisheyeFrameError(raw, circles, 10), "odd width"));
  EXPECT_THROW(SplitDualFisheye(raw, circles), std::invalid_argument);
  EXPECT_TRUE(Contains(DualFisheyeLayoutError(cv::Mat()), "empty"));
  EXPECT_TRUE(Contains(DualFisheyeLayoutError(cv::Mat(4, 8, CV_32FC1)),
                       "8-bit or 16-bit"));
  EXPECT_EQ(DualFisheyeLayoutError(cv::Mat(40, 80, CV_16UC4)), "");
}

TEST(DualFisheyeSplit, RefusesACircleOutsideItsLensImage) {
  const cv::Size lens_size(100, 80);
  EXPECT_EQ(ImageCircleError(ImageCircle{50, 40, 40}, lens_size), "");
  EXPECT_TRUE(Contains(ImageCircleError(ImageCircle{50, 40, 40.5}, lens_size),
                       "goes outside the 100x80 lens image (by 0.5 px on "
                       "the top)"));
  EXPECT_TRUE(Contains(ImageCircleError(ImageCircle{70, 40, 35}, lens_size),
                       "on the right"));
  EXPECT_TRUE(Contains(ImageCircleError(ImageCircle{50, 40, 0}, lens_size),
                       "radius <= 0"));
  EXPECT_TRUE(Contains(ImageCircleError(ImageCircle{NAN, 40, 10}, lens_size),
                       "not finite"));

  const cv::Mat raw(80, 200, CV_8UC1, cv::Scalar::all(0));
  try {
    SplitDualFisheye(raw, {ImageCircle{50, 40, 30}, ImageCircle{10, 40, 30}});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_TRUE(Contains(error.what(), "lens 1"));
    EXPECT_TRUE(Contains(error.what(), "(cx, cy, r) = (10, 40, 30)"));
    EXPECT_TRUE(Contains(error.what(), "by 20 px on the left"));
  }

  // A detected circle may overshoot by up to 1 px; it is then shrunk.
  const ImageCircle shrunk =
      ClampDetectedImageCircle(ImageCircle{50, 40, 40.6}, lens_size);
  EXPECT_EQ(shrunk.r, 40);
  const ImageCircle kept =
      ClampDetectedImageCircle(ImageCircle{50, 40, 41.5}, lens_size);
  EXPECT_EQ(kept.r, 41.5);
}

TEST(DualFisheyeSplit, TakesTheMedianOfDetectedCircles) {
  const ImageCircle median = MedianImageCircle({ImageCircle{10, 20, 30},
                                                ImageCircle{11, 25, 29},
                                                ImageCircle{50, 0, 1}});
  EXPECT_EQ(median.cx, 11);
  EXPECT_EQ(median.cy, 20);
  EXPECT_EQ(median.r, 29);
  EXPECT_EQ(
      MedianImageCircle({ImageCircle{10, 20, 30}, ImageCircle{11, 21, 31}}).cx,
      10.5);
  EXPECT_THROW(MedianImageCircle({}), std::invalid_argument);
}

TEST(DualFisheyeSplit, ParsesCircles) {
  std::array<ImageCircle, 2> circles;
  ASSERT_EQ(ParseImageCircles("480,480.5,470; 1.5e2, 2,3", &circles), "");
  EXPECT_EQ(circles[0].cx, 480);
  EXPECT_EQ(circles[0].cy, 480.5);
  EXPECT_EQ(circles[0].r, 470);
  EXPECT_EQ(circles[1].cx, 150);
  EXPECT_EQ(circles[1].cy, 2);
  EXPECT_EQ(circles[1].r, 3);
  for (const char* bad : {"",
                          "1,2,3",
                          "1,2,3;4,5",
                          "1,2,3;4,5,6;7,8,9",
                          "1,2,3;4,x,6",
                          "1,2,3;4,5,6,",
                          "1,2,3;4,nan,6"}) {
    EXPECT_TRUE(
        Contains(ParseImageCircles(bad, &circles), "expected two circles"))
        << bad;
  }
  EXPECT_EQ(ShortestDoubleText(0.1), "0.1");
  EXPECT_EQ(ShortestDoubleText(480), "480");
}

}  // namespace
}  // namespace colmap
