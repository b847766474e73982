// A lens's light fall-off towards the rim of its image circle (vignetting),
// estimated from the lens's own images and divided out before features are
// extracted (`dual_fisheye_splitter --flat_field 1`).
//
// A fisheye passes less light towards the rim of its circle. The darker
// rim moves keypoints (a blob on a brightness slope is found off its
// centre, towards the brighter side) and so biases what the rims see,
// which is where the two lenses of a 360° camera overlap and what fixes
// their offset. The fall-off is radial about the circle's centre: from
// every image of a lens, the mean grey value at each radius (fraction of
// the circle's radius) relative to the image's mean, the median over the
// images (scenes differ, the lens does not), fitted by a level times
// V(rho) = 1 + a rho^2 + b rho^4, V(0) = 1 (constant past its lowest
// point).
#pragma once

#include "colmap_ext/image/dual_fisheye_split.h"

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace colmap {

struct RadialFalloff {
  // V(rho) = 1 + a rho^2 + b rho^4, constant past its lowest point in
  // rho; a = b = 0: no correction.
  double a = 0;
  double b = 0;
  double Gain(double rho) const;  // V(rho)
  bool IsIdentity() const { return a == 0 && b == 0; }
};

class RadialFalloffEstimator {
 public:
  // Radii (fractions of the circle's radius) are binned this finely.
  static constexpr int kNumBins = 40;

  RadialFalloffEstimator(const ImageCircle& circle, int black_level);

  // One image of the lens (8-bit, grey or colour, the lens image's size):
  // its mean grey value per radius, relative to its mean. Pixels at or
  // below the black level or saturated are left out. An image without
  // enough valid pixels is skipped.
  void Add(const cv::Mat& image);

  int NumImages() const { return static_cast<int>(profiles_.size()); }

  // The fall-off fitted to the median profile; the identity when fewer
  // than min_images were added, when the fit darkens the rim by less than
  // min_falloff, or when it is not monotonically darker outwards (the
  // scenes, not the lens). WHY (may be null) says which.
  RadialFalloff Fit(int min_images = 3,
                    double min_falloff = 0.03,
                    std::string* why = nullptr) const;

 private:
  ImageCircle circle_;
  int black_level_;
  std::vector<std::vector<double>> profiles_;  // per image, kNumBins (NaN)
};

// IMAGE (8-bit, any channels) divided by FALLOFF's gain at each pixel's
// radius inside CIRCLE (saturating at 255); pixels outside are unchanged.
void DivideByFalloff(const ImageCircle& circle,
                     const RadialFalloff& falloff,
                     cv::Mat* image);

}  // namespace colmap
