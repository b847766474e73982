#include "colmap_ext/image/dual_fisheye_split.h"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

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

// RAW's two lens images cut to CIRCLES, as the splitter does for a frame
// with both circles in one file; throws std::invalid_argument where RAW
// fails DualFisheyeLayoutError or a circle CutImageCircle's checks.
std::array<LensImage, 2> SplitDualFisheye(
    const cv::Mat& raw, const std::array<ImageCircle, 2>& circles) {
  if (const std::string error = DualFisheyeLayoutError(raw); !error.empty()) {
    throw std::invalid_argument(error);
  }
  const std::array<cv::Mat, 2> lens_images = LensImagesOfRawFrame(raw);
  return {CutImageCircle(lens_images[0], circles[0]),
          CutImageCircle(lens_images[1], circles[1])};
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
  // left out; a fit that overshoots by a fraction of a pixel is a valid
  // circle (circles may reach past the image).
  const int size = 120;
  const ImageCircle circle{60, 60, 60};
  const cv::Mat raw = MakeRawFrame(size, size, CV_8UC1, {circle, circle});
  ImageCircle detected;
  ASSERT_EQ(DetectImageCircle(raw(cv::Rect(0, 0, size, size)), 10, &detected),
            "");
  EXPECT_NEAR(detected.cx, 60, 1.0);
  EXPECT_NEAR(detected.cy, 60, 1.0);
  EXPECT_NEAR(detected.r, 60, 1.0);
  EXPECT_EQ(ImageCircleError(detected, cv::Size(size, size)), "");
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

TEST(DualFisheyeSplit, RefusesAFrameWhosePictureGoesOnAcrossTheCircles) {
  const int size = 64;
  const std::array<ImageCircle, 2> circles = {ImageCircle{32, 32, 30},
                                              ImageCircle{32, 32, 30}};
  cv::Mat raw = MakeRawFrame(size, size, CV_8UC3, circles);
  EXPECT_EQ(DualFisheyeFrameError(LensImagesOfRawFrame(raw), circles, 10), "");
  int num_directions = 0;
  EXPECT_EQ(DarkRimFraction(
                LensImagesOfRawFrame(raw)[0], circles[0], 10, &num_directions),
            1.0);
  EXPECT_GT(num_directions, 100);

  // Noise around the black level and a few bright specks pass; so does a
  // dark grey surround above the black level (a housing): outside a lens's
  // circle is dark, not black.
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
  EXPECT_EQ(DualFisheyeFrameError(LensImagesOfRawFrame(noisy), circles, 10),
            "");
  EXPECT_EQ(DualFisheyeFrameError(LensImagesOfRawFrame(noisy), circles, 5), "");
  // In 16-bit images the black level is scaled by 257.
  cv::Mat raw16;
  noisy.convertTo(raw16, CV_16U, 257);
  EXPECT_EQ(DualFisheyeFrameError(LensImagesOfRawFrame(raw16), circles, 10),
            "");

  // A normal photo (texture everywhere) is refused, naming the lens; so is
  // a frame whose right lens is a photo.
  cv::Mat photo(size, 2 * size, CV_8UC3);
  cv::randu(photo, cv::Scalar::all(0), cv::Scalar::all(256));
  EXPECT_TRUE(
      Contains(DualFisheyeFrameError(LensImagesOfRawFrame(photo), circles, 10),
               "lens 0: only"));
  EXPECT_TRUE(
      Contains(DualFisheyeFrameError(LensImagesOfRawFrame(photo), circles, 10),
               "not a dual-fisheye frame"));
  cv::Mat half_photo = raw.clone();
  photo(cv::Rect(size, 0, size, size))
      .copyTo(half_photo(cv::Rect(size, 0, size, size)));
  EXPECT_TRUE(Contains(
      DualFisheyeFrameError(LensImagesOfRawFrame(half_photo), circles, 10),
      "lens 1: only"));
  // All black inside: nothing to tell a lens from.
  EXPECT_TRUE(Contains(
      LensImageCircleError(cv::Mat::zeros(size, size, CV_8UC1), circles[0], 10),
      "no part of the rim"));
}

TEST(DualFisheyeSplit, RefusesAnOddWidth) {
  const cv::Mat raw(40, 81, CV_8UC3, cv::Scalar::all(0));
  EXPECT_TRUE(Contains(DualFisheyeLayoutError(raw), "odd width 81"));
  const std::array<ImageCircle, 2> circles = {ImageCircle{20, 20, 10},
                                              ImageCircle{20, 20, 10}};
  EXPECT_THROW(SplitDualFisheye(raw, circles), std::invalid_argument);
  // Lens images of separate files must agree in size and type.
  const std::array<cv::Mat, 2> unequal = {cv::Mat(40, 40, CV_8UC3),
                                          cv::Mat(40, 42, CV_8UC3)};
  EXPECT_TRUE(Contains(DualFisheyeFrameError(unequal, circles, 10),
                       "the lens images differ: 40x40"));
  EXPECT_TRUE(Contains(DualFisheyeLayoutError(cv::Mat()), "empty"));
  EXPECT_TRUE(Contains(DualFisheyeLayoutError(cv::Mat(4, 8, CV_32FC1)),
                       "8-bit or 16-bit"));
  EXPECT_EQ(DualFisheyeLayoutError(cv::Mat(40, 80, CV_16UC4)), "");
}

TEST(DualFisheyeSplit, AcceptsCroppedCirclesAndRefusesAbsurdOnes) {
  // Real cameras crop their image circles at the frame's edges: a circle
  // reaching past the image is valid (this was refused before), and its
  // mask is its part inside the image.
  const cv::Size lens_size(100, 80);
  EXPECT_EQ(ImageCircleError(ImageCircle{50, 40, 40}, lens_size), "");
  EXPECT_EQ(ImageCircleError(ImageCircle{50, 40, 40.5}, lens_size), "");
  EXPECT_EQ(ImageCircleError(ImageCircle{70, 40, 35}, lens_size), "");
  EXPECT_EQ(ImageCircleError(ImageCircle{50, 40, 60}, lens_size), "");
  EXPECT_EQ(ImageCircleError(ImageCircle{0, 80, 60}, lens_size), "");
  EXPECT_TRUE(Contains(ImageCircleError(ImageCircle{50, 40, 0}, lens_size),
                       "radius <= 0"));
  EXPECT_TRUE(Contains(ImageCircleError(ImageCircle{NAN, 40, 10}, lens_size),
                       "not finite"));
  EXPECT_TRUE(Contains(ImageCircleError(ImageCircle{-0.5, 40, 30}, lens_size),
                       "its centre is outside the 100x80 lens image"));
  EXPECT_TRUE(Contains(ImageCircleError(ImageCircle{50, 81, 30}, lens_size),
                       "its centre is outside"));
  // The diagonal is 128.06: 2x is 256.1.
  EXPECT_EQ(ImageCircleError(ImageCircle{50, 40, 256}, lens_size), "");
  EXPECT_TRUE(Contains(ImageCircleError(ImageCircle{50, 40, 257}, lens_size),
                       "more than twice the diagonal"));
  // About 316 of 8000 pixels (pi 10^2 = 314); r = 23: 20.7%.
  EXPECT_TRUE(Contains(ImageCircleError(ImageCircle{50, 40, 10}, lens_size),
                       "covers 4.0% of the 100x80 lens image"));
  EXPECT_EQ(ImageCircleError(ImageCircle{50, 40, 23}, lens_size), "");

  const cv::Mat raw(80, 200, CV_8UC1, cv::Scalar::all(0));
  try {
    CutImageCircle(LensImagesOfRawFrame(raw)[1], ImageCircle{150, 40, 30});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_TRUE(Contains(error.what(), "(cx, cy, r) = (150, 40, 30)"));
    EXPECT_TRUE(Contains(error.what(), "centre is outside"));
  }

  // The split of a cropped circle: mask = circle and image, pixel by pixel.
  cv::Mat textured(80, 200, CV_8UC3);
  cv::randu(textured, cv::Scalar::all(1), cv::Scalar::all(256));
  const std::array<ImageCircle, 2> cropped = {ImageCircle{50.5, 38.25, 47.5},
                                              ImageCircle{12.0, 70.0, 64.0}};
  const std::array<LensImage, 2> lenses = SplitDualFisheye(textured, cropped);
  for (int lens = 0; lens < 2; ++lens) {
    int num_inside = 0;
    for (int y = 0; y < 80; ++y) {
      for (int x = 0; x < 100; ++x) {
        const bool inside = Inside(x, y, cropped[lens]);
        num_inside += inside;
        ASSERT_EQ(lenses[lens].mask.at<uchar>(y, x), inside ? 255 : 0)
            << "lens " << lens << " " << x << "," << y;
        ASSERT_EQ(lenses[lens].image.at<cv::Vec3b>(y, x),
                  inside ? textured.at<cv::Vec3b>(y, lens * 100 + x)
                         : cv::Vec3b(0, 0, 0));
      }
    }
    // Cropped: fewer pixels inside than the whole disc.
    EXPECT_LT(num_inside, CV_PI * cropped[lens].r * cropped[lens].r - 100);
    EXPECT_GT(num_inside, 1000);
  }
}

// A lens image as a real camera writes it: a smooth picture inside a circle
// that reaches past the top and bottom of the image, darkening over its
// last 2% (vignetting), a dark band at the lens's edge, then a textured grey
// housing ring and black; flare brightens the housing on one side. The old
// bright/black boundary takes the housing for the circle.
cv::Mat MakeHousedLensImage(const cv::Size& size,
                            const ImageCircle& circle,
                            unsigned seed) {
  cv::theRNG().state = seed;
  cv::Mat coarse(size.height / 16 + 2, size.width / 16 + 2, CV_32FC3);
  cv::randu(coarse, cv::Scalar::all(60), cv::Scalar::all(230));
  cv::Mat picture;
  cv::resize(coarse, picture, size, 0, 0, cv::INTER_CUBIC);
  cv::Mat grain(size, CV_32FC3);
  cv::randn(grain, cv::Scalar::all(0), cv::Scalar::all(6));
  cv::Mat housing(size, CV_32FC3);
  cv::randu(housing, cv::Scalar::all(35), cv::Scalar::all(70));
  cv::Mat image(size, CV_8UC3);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const double d =
          std::hypot(x + 0.5 - circle.cx, y + 0.5 - circle.cy) / circle.r;
      cv::Vec3f value;
      if (d <= 1.0) {
        const double vignetting = std::clamp((1.0 - d) / 0.02, 0.0, 1.0);
        value = picture.at<cv::Vec3f>(y, x) * (0.3 + 0.7 * vignetting);
      } else if (d <= 1.025) {
        value = cv::Vec3f::all(8);  // the lens's dark edge
      } else if (d <= 1.2) {
        value = housing.at<cv::Vec3f>(y, x);
        // Flare: up to +60 on the left side of the housing.
        value += cv::Vec3f::all(static_cast<float>(
            std::max(0.0, 60.0 * (1 - (x + 0.5) / (0.4 * size.width)))));
      } else {
        value = cv::Vec3f::all(3);
      }
      value += grain.at<cv::Vec3f>(y, x);
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(value[0]),
                                            cv::saturate_cast<uchar>(value[1]),
                                            cv::saturate_cast<uchar>(value[2]));
    }
  }
  return image;
}

TEST(DualFisheyeSplit, DetectsACroppedCircleInsideAHousingRingWithFlare) {
  const cv::Size size(420, 400);
  // 2 x 206 > 400: cropped by 6 px at the top and 10 at the bottom.
  const std::array<ImageCircle, 2> circles = {ImageCircle{211.3, 198.2, 206.4},
                                              ImageCircle{206.0, 202.5, 204.0}};
  for (int lens = 0; lens < 2; ++lens) {
    const cv::Mat image = MakeHousedLensImage(size, circles[lens], 40 + lens);
    // The housing is far above the black level: a bright area of radius
    // 1.2 r, which the circle must not be taken for.
    ImageCircle detected;
    ASSERT_EQ(DetectImageCircle(image, 10, &detected), "") << "lens " << lens;
    EXPECT_NEAR(detected.cx, circles[lens].cx, 2.0) << "lens " << lens;
    EXPECT_NEAR(detected.cy, circles[lens].cy, 2.0) << "lens " << lens;
    EXPECT_NEAR(detected.r, circles[lens].r, 2.0) << "lens " << lens;
    EXPECT_EQ(ImageCircleError(detected, size), "");
    EXPECT_EQ(LensImageCircleError(image, detected, 10), "");
    EXPECT_EQ(LensImageCircleError(image, circles[lens], 10), "");
    // 16-bit the same.
    cv::Mat image16;
    image.convertTo(image16, CV_16U, 257);
    ImageCircle detected16;
    ASSERT_EQ(DetectImageCircle(image16, 10, &detected16), "");
    EXPECT_NEAR(detected16.r, detected.r, 0.5);
  }
}

TEST(DualFisheyeSplit, TellsAHousedFrameFromAPhotoAndAPanorama) {
  const cv::Size size(420, 400);
  const std::array<ImageCircle, 2> circles = {ImageCircle{211.3, 198.2, 206.4},
                                              ImageCircle{206.0, 202.5, 204.0}};
  const std::array<cv::Mat, 2> housed = {
      MakeHousedLensImage(size, circles[0], 50),
      MakeHousedLensImage(size, circles[1], 51)};
  EXPECT_EQ(DualFisheyeFrameError(housed, circles, 10), "");
  EXPECT_GT(DarkRimFraction(housed[0], circles[0], 10), 0.9);

  // A normal photo: a smooth picture across the whole frame (its halves).
  cv::theRNG().state = 52;
  cv::Mat coarse(size.height / 16 + 2, 2 * size.width / 16 + 2, CV_8UC3);
  cv::randu(coarse, cv::Scalar::all(20), cv::Scalar::all(240));
  cv::Mat photo;
  cv::resize(coarse,
             photo,
             cv::Size(2 * size.width, size.height),
             0,
             0,
             cv::INTER_CUBIC);
  EXPECT_TRUE(
      Contains(DualFisheyeFrameError(LensImagesOfRawFrame(photo), circles, 10),
               "not a dual-fisheye frame"));
  EXPECT_LT(DarkRimFraction(LensImagesOfRawFrame(photo)[0], circles[0], 10),
            0.3);
  // No circle is found in it either.
  ImageCircle detected;
  EXPECT_TRUE(
      Contains(DetectImageCircle(LensImagesOfRawFrame(photo)[0], 10, &detected),
               "no image circle found"));

  // An equirectangular panorama: bright sky above, darker ground below a
  // horizon, textured; its halves hold no dark-rimmed circle.
  cv::Mat panorama = photo.clone();
  for (int y = 0; y < size.height; ++y) {
    const double light = y < size.height / 2 ? 1.0 : 0.45;
    for (int x = 0; x < 2 * size.width; ++x) {
      cv::Vec3b& pixel = panorama.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) {
        pixel[c] = cv::saturate_cast<uchar>(pixel[c] * light);
      }
    }
  }
  EXPECT_TRUE(Contains(
      DualFisheyeFrameError(LensImagesOfRawFrame(panorama), circles, 10),
      "not a dual-fisheye frame"));
}

// A picture of flat patches (cells of 12 px, intensities 20 to 230).
cv::Mat MakePatchPicture(int size, unsigned seed) {
  cv::theRNG().state = seed;
  cv::Mat coarse(size / 12 + 2, size / 12 + 2, CV_32FC1);
  cv::randu(coarse, cv::Scalar::all(20), cv::Scalar::all(230));
  cv::Mat picture;
  cv::resize(coarse, picture, cv::Size(size, size), 0, 0, cv::INTER_NEAREST);
  return picture(cv::Rect(0, 0, size, size)).clone();
}

// A lens image as sphera_render --realistic draws it: the picture darkened
// towards the circle by vignetting (35% at the rim), then a housing ring
// brightest at its inner edge (82 DN, where the front element's rim catches
// light, fading to 27 DN at 1.15 r), noise, and a dark surround. Beside a
// dark patch the housing is brighter than the picture, beside a bright one
// darker, and beside a middle one about as bright.
cv::Mat MakeBrightHousingLensImage(int size, const ImageCircle& circle,
                                   unsigned seed) {
  const cv::Mat picture = MakePatchPicture(size, seed);
  cv::Mat noise(size, size, CV_32FC1);
  cv::randn(noise, cv::Scalar::all(0), cv::Scalar::all(2));
  cv::Mat image(size, size, CV_8UC1);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double d =
          std::hypot(x + 0.5 - circle.cx, y + 0.5 - circle.cy) / circle.r;
      double value;
      if (d <= 1.0) {
        value = picture.at<float>(y, x) * (1.0 - 0.35 * d * d);
      } else if (d <= 1.15) {
        value = 55 * (1.5 - (d - 1) / 0.15);
      } else {
        value = 14;
      }
      image.at<uchar>(y, x) =
          cv::saturate_cast<uchar>(value + noise.at<float>(y, x));
    }
  }
  return image;
}

TEST(DualFisheyeSplit, TellsABrightHousingFromAPhoto) {
  const int size = 480;
  const ImageCircle circle{240, 240, 208};
  const cv::Mat housed = MakeBrightHousingLensImage(size, circle, 7);
  EXPECT_GT(DarkRimFraction(housed, circle, 10), kMinDarkRimFraction);
  EXPECT_EQ(LensImageCircleError(housed, circle, 10), "");

  // The same picture going on across the circle (a normal photo): refused.
  cv::Mat photo;
  MakePatchPicture(size, 7).convertTo(photo, CV_8UC1);
  EXPECT_LT(DarkRimFraction(photo, circle, 10), kMinDarkRimFraction);
  EXPECT_TRUE(Contains(LensImageCircleError(photo, circle, 10),
                       "not a dual-fisheye frame"));
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
