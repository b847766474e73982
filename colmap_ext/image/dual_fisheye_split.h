// Splitting the frames of a dual-fisheye camera (Insta360, Ricoh Theta: two
// image circles side by side in one image; GoPro Fusion: one file per lens)
// into one image per lens plus a mask of its image circle, and finding the
// image circles. OpenCV and the standard library only.
//
// Layout: a raw frame of width 2W and height H is [lens0 | lens1], lens0 the
// left W columns, lens1 the right W columns. An image circle (cx, cy, r) is
// in its lens image's own pixel coordinates, COLMAP's convention: the
// upper-left corner of the image is (0, 0), the centre of pixel (x, y) is
// (x + 0.5, y + 0.5); a pixel is inside iff its centre is (in double):
//   (x + 0.5 - cx)^2 + (y + 0.5 - cy)^2 <= r^2.
// A circle may reach past the lens image's edges (real cameras crop their
// circles): what is inside is the circle's part inside the image.
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

// One lens image: its pixels copied exactly, those outside its image circle
// set to 0 (all channels), and its mask (CV_8UC1, 255 inside the circle, 0
// outside).
struct LensImage {
  cv::Mat image;
  cv::Mat mask;
};

// An image circle must cover at least this fraction of its lens image: less
// is a circle of another image size or a typing error, not a lens.
inline constexpr double kMinImageCircleCoverage = 0.2;

// A frame is dual-fisheye when, in each lens, at least this fraction of the
// visible rim of its image circle ends the picture: dark on the outside
// (the lens's edge, then its housing or black), or the bright inner edge of
// a housing beside a darker picture. Flare, housing parts as bright as the
// picture and vignetting leave some of the rim unchanged (a rendered
// consumer camera with a bright housing: 31-45% of the rim dark outside);
// a normal photo or a stitched panorama, whose pictures go on across any
// circle, leave most of it (the real panoramas of the shared data: 4-17%).
inline constexpr double kMinDarkRimFraction = 0.35;

// Why RAW cannot be a side-by-side dual-fisheye frame by its size and type
// (LensImageError, or an odd width), or "".
std::string DualFisheyeLayoutError(const cv::Mat& raw);

// Why IMAGE cannot be a lens image (empty, not 8/16-bit, more than 4
// channels), or "".
std::string LensImageError(const cv::Mat& image);

// The size of each lens image of a raw frame of size RAW_SIZE (W x H).
cv::Size LensImageSize(const cv::Size& raw_size);

// The two lens images of RAW (views of its halves, not copies). RAW must
// pass DualFisheyeLayoutError.
std::array<cv::Mat, 2> LensImagesOfRawFrame(const cv::Mat& raw);

// Why CIRCLE cannot be the image circle of a lens image of LENS_SIZE: not
// finite, radius <= 0, its centre outside the image, its radius more than
// twice the image's diagonal, or its part inside the image less than
// kMinImageCircleCoverage of the image; or "". Reaching past the image's
// edges is normal.
std::string ImageCircleError(const ImageCircle& circle,
                             const cv::Size& lens_size);

// The mask of CIRCLE in an image of SIZE: CV_8UC1, 255 inside, 0 outside.
// The one definition of "inside" that everything here uses.
cv::Mat ImageCircleMask(const cv::Size& size, const ImageCircle& circle);

// CV_8UC1 mask of the pixels of IMAGE brighter than BLACK_LEVEL (255).
cv::Mat BrightPixelMask(const cv::Mat& image, int black_level);

// The fraction of the visible rim of CIRCLE in LENS_IMAGE that is dark on
// the outside. Along rays from the circle's centre at 360 directions, the
// mean intensity in a band just inside the circle is compared with that in
// bands just outside it (each max(2 px, 2% of r) wide, max(1 px, 0.5% of r)
// away from the circle, so that the lens's blurred edge counts for
// neither): the rim is dark there when the darkest of three outside bands
// side by side is at most 60% of the inside, or when the first of them is
// at least the inside over 60% and brighter than the last (a housing's
// bright rim, fading outwards). Three, so that a circle given a little
// inside the picture's edge (a conservative circle from a maker's file, 1-3%
// of r) still finds the dark beyond it. Only directions whose
// first outside band is in the image and whose inside band is brighter than
// BLACK_LEVEL count; *NUM_DIRECTIONS (if not null) is set to their number,
// and the fraction is 0 when there is none.
double DarkRimFraction(const cv::Mat& lens_image,
                       const ImageCircle& circle,
                       int black_level,
                       int* num_directions = nullptr);

// Why LENS_IMAGE with CIRCLE is not a lens image of a dual-fisheye camera:
// less than kMinDarkRimFraction of its circle's rim is dark outside (gives
// the percentage: a normal photo or a half of an equirectangular
// panorama), or no part of the rim is in the image with the picture inside
// it brighter than BLACK_LEVEL; or "". CIRCLE must pass ImageCircleError.
std::string LensImageCircleError(const cv::Mat& lens_image,
                                 const ImageCircle& circle,
                                 int black_level);

// Why LENS_IMAGES with CIRCLES are not the two lens images of one
// dual-fisheye frame: either fails LensImageError, they differ in size or
// type, or a lens fails LensImageCircleError (named "lens 0" or "lens 1");
// or "". The circles must pass ImageCircleError.
std::string DualFisheyeFrameError(const std::array<cv::Mat, 2>& lens_images,
                                  const std::array<ImageCircle, 2>& circles,
                                  int black_level);

// Detects the image circle of a lens image by its edge, where the picture
// ends and the lens's dark edge, housing or black surround begins; none of
// these need be black, and the circle may reach past the image's edges.
//
// The intensity is blurred (sigma max(1 px, 0.1% of the smaller side)).
// Along 720 rays from the image's centre, the places where the mean
// intensity over a window (1% of the image's smaller side, at least 2 px)
// before a point exceeds that after it by the most (local maxima, located
// to a fraction of a pixel), and the outside is at most 60% of the inside,
// are edge candidates (the 4 strongest a ray). A circle is found among them
// by RANSAC (6000 triples of candidates on rays at least 60 degrees apart,
// a fixed seed; a camera centres its circles, so the centre within 20% of
// the smaller side of the image's centre and a radius from 25% of the
// smaller side to the diagonal; the score is the summed strength of the
// strongest candidate of each ray within max(1.5 px, 1% of r) of the
// circle, so that the strong edge of the image circle
// beats the weak outer edge of a housing, and the tolerance takes the soft
// edge of a real lens, whose steepest point moves with the brightness of
// the picture at the rim), fitted to its inliers by least squares (Kasa),
// refitted until the inliers no longer change, and then refined twice from
// rays cast from its own centre (the strongest edge within a band of
// max(3 windows, 3% of r) around the circle, a ray). Scene edges, a housing
// ring and flare are outliers. When the surround is black, so that the
// circle bounding the pixels brighter than BLACK_LEVEL agrees with the edge
// within max(2 px, 1% of r), that circle is returned instead: a hard-edged
// disc's own mask comes back pixel for pixel.
//
// Returns "" and sets *CIRCLE, or why no circle was found: too few edge
// candidates, or the edges near the best circle cover too little of its
// rim inside the image (fewer than 16 rays, less than half of the rays
// that cross it inside the image, or less than 3/4 of the 45-degree
// directions those rays are in, or fewer than 3). The circle is not
// checked against the image size (ImageCircleError does that).
std::string DetectImageCircle(const cv::Mat& lens_image,
                              int black_level,
                              ImageCircle* circle);

// The median of CIRCLES (not empty), of cx, cy and r apart: the image
// circle of a lens from its detections in many frames, a few of which may
// be off (dark scenes, stray light).
ImageCircle MedianImageCircle(const std::vector<ImageCircle>& circles);

// LENS_IMAGE with CIRCLE its image circle: the pixels outside it black, and
// its mask. Throws std::invalid_argument when LENS_IMAGE fails
// LensImageError or CIRCLE fails ImageCircleError.
LensImage CutImageCircle(const cv::Mat& lens_image, const ImageCircle& circle);

// Parses "cx,cy,r;cx,cy,r" (lens0; lens1). Returns "" and sets *CIRCLES, or
// why TEXT is not two circles.
std::string ParseImageCircles(const std::string& text,
                              std::array<ImageCircle, 2>* circles);

// VALUE as the shortest decimal text that reads back to it.
std::string ShortestDoubleText(double value);

}  // namespace colmap
