// Splitting the raw frames of a dual-fisheye camera (Insta360, Ricoh Theta):
// two image circles side by side in one image become one image per lens
// plus a mask of its image circle. OpenCV and the standard library only.
//
// Layout: a raw frame of width 2W and height H is [lens0 | lens1], lens0 the
// left W columns, lens1 the right W columns. An image circle (cx, cy, r) is
// in its lens image's own pixel coordinates, COLMAP's convention: the
// upper-left corner of the image is (0, 0), the centre of pixel (x, y) is
// (x + 0.5, y + 0.5); a pixel is inside iff its centre is (in double):
//   (x + 0.5 - cx)^2 + (y + 0.5 - cy)^2 <= r^2.
//
// Images are 8-bit or 16-bit with 1 to 4 channels; a pixel's intensity is
// the largest of its colour channels (an alpha channel, the 4th, does not
// count). A black level is on the 8-bit scale and is multiplied by 257 for
// 16-bit images; a pixel is black iff its intensity <= the black level.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace colmap {

struct ImageCircle {
  double cx = 0;
  double cy = 0;
  double r = 0;
};

// One lens image of a raw frame: its pixels copied exactly, those outside
// its image circle set to 0 (all channels), and its mask (CV_8UC1, 255
// inside the circle, 0 outside).
struct LensImage {
  cv::Mat image;
  cv::Mat mask;
};

// A frame is refused as not dual-fisheye when more than this fraction of its
// pixels outside both image circles are brighter than the black level: a
// normal photo or an equirectangular panorama of the same 2:1 size, not a
// camera's black surround with some noise or stray light.
inline constexpr double kMaxBrightFractionOutsideCircles = 0.05;

// A detected circle may overshoot its lens image by this much (pixels),
// the detection's uncertainty for a circle that touches the image's edges;
// it is then shrunk to fit (ClampDetectedImageCircle). More is an error.
inline constexpr double kMaxDetectedCircleOvershootPx = 1.0;

// Why RAW cannot be a dual-fisheye frame by its size and type (empty, odd
// width, not 8/16-bit, more than 4 channels), or "".
std::string DualFisheyeLayoutError(const cv::Mat& raw);

// The size of each lens image of a raw frame of size RAW_SIZE (W x H).
cv::Size LensImageSize(const cv::Size& raw_size);

// Why CIRCLE is not a valid image circle of a lens image of LENS_SIZE: not
// finite, radius <= 0, or the disc [cx - r, cx + r] x [cy - r, cy + r] not
// inside [0, W] x [0, H] (names the side and by how much); or "".
std::string ImageCircleError(const ImageCircle& circle,
                             const cv::Size& lens_size);

// CIRCLE's radius shrunk so that the disc fits LENS_SIZE, when it overshoots
// by at most kMaxDetectedCircleOvershootPx; otherwise CIRCLE unchanged (and
// ImageCircleError says why it is refused).
ImageCircle ClampDetectedImageCircle(const ImageCircle& circle,
                                     const cv::Size& lens_size);

// The mask of CIRCLE in an image of SIZE: CV_8UC1, 255 inside, 0 outside.
// The one definition of "inside" that everything here uses.
cv::Mat ImageCircleMask(const cv::Size& size, const ImageCircle& circle);

// CV_8UC1 mask of the pixels of IMAGE brighter than BLACK_LEVEL (255).
cv::Mat BrightPixelMask(const cv::Mat& image, int black_level);

// The fraction of RAW's pixels outside both image circles (CIRCLES[i] in
// lens i) that are brighter than BLACK_LEVEL; 0 when no pixel is outside.
// RAW must pass DualFisheyeLayoutError.
double BrightFractionOutsideCircles(const cv::Mat& raw,
                                    const std::array<ImageCircle, 2>& circles,
                                    int black_level);

// Why RAW is not a dual-fisheye frame with CIRCLES: its layout, or more than
// kMaxBrightFractionOutsideCircles of the pixels outside the circles are
// brighter than BLACK_LEVEL (gives the percentage); or "". The circles must
// pass ImageCircleError for RAW's lens size.
std::string DualFisheyeFrameError(const cv::Mat& raw,
                                  const std::array<ImageCircle, 2>& circles,
                                  int black_level);

// Detects the image circle of a lens image: the circle bounding its pixels
// brighter than BLACK_LEVEL. Boundary points are where each row and each
// column enters and leaves the bright pixels (on the pixel edge between the
// last black and the first bright pixel, so a hard-edged disc gives points
// within half a pixel of its circle); points on the image's border are left
// out (the circle may touch it, the bright area may be cut by it). A circle
// is fitted to them by algebraic least squares (Kasa), then refitted to the
// points within max(1.5 px, 3 x the median distance) of the last fit until
// the inliers no longer change: dark scene content near the rim and bright
// specks in the black surround fall out as outliers. Last, with the centre
// fixed, the radius is moved (by at most 1 px) to where it misclassifies
// the fewest pixels within 2 px of the circle (bright inside, black
// outside): a hard-edged disc's own mask comes back pixel for pixel when
// the centre is close enough. Returns "" and sets *CIRCLE, or why no
// circle was found (too few boundary points, most of them not on one
// circle, or they do not surround a centre). The circle is not checked
// against the image size (ImageCircleError does that).
std::string DetectImageCircle(const cv::Mat& lens_image,
                              int black_level,
                              ImageCircle* circle);

// The median of CIRCLES (not empty), of cx, cy and r apart: the image
// circle of a lens from its detections in many frames, a few of which may
// be off (dark scenes, stray light).
ImageCircle MedianImageCircle(const std::vector<ImageCircle>& circles);

// Splits RAW into its two lens images with CIRCLES[i] the image circle of
// lens i. Throws std::invalid_argument when RAW fails DualFisheyeLayoutError
// or a circle fails ImageCircleError.
std::array<LensImage, 2> SplitDualFisheye(
    const cv::Mat& raw, const std::array<ImageCircle, 2>& circles);

// Parses "cx,cy,r;cx,cy,r" (lens0; lens1). Returns "" and sets *CIRCLES, or
// why TEXT is not two circles.
std::string ParseImageCircles(const std::string& text,
                              std::array<ImageCircle, 2>* circles);

// VALUE as the shortest decimal text that reads back to it.
std::string ShortestDoubleText(double value);

}  // namespace colmap
