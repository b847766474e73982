// Parameter checks for models whose projection can fold: a fitted polynomial
// (Kannala-Brandt, OCamCalib) is monotone only up to some angle, and beyond it
// two rays share a pixel. Such parameters are refused when the image reaches
// past the fold (pixels there have no ray of the model); a fold outside the
// image is harmless and accepted.
#pragma once

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

namespace sphera {
namespace internal {

inline std::string FormatFixed(double value, int decimals) {
  std::ostringstream stream;
  stream << std::fixed << std::setprecision(decimals) << value;
  return stream.str();
}

// "<MODEL>: projection folds at 97.3° (r = 812.4 px), inside the 1600x1088
// image: <where>".
inline std::string FoldMessage(const char* model_name, double fold_angle_rad,
                               double fold_radius_px, int width, int height,
                               const std::string& where) {
  constexpr double kRadToDeg = 57.29577951308232;
  return std::string(model_name) + ": projection folds at " +
         FormatFixed(fold_angle_rad * kRadToDeg, 1) +
         "° (r = " + FormatFixed(fold_radius_px, 1) + " px), inside the " +
         std::to_string(width) + "x" + std::to_string(height) +
         " image: " + where;
}

// The fold message if the image [0, width] x [0, height] holds a pixel beyond
// a fold at radial coordinate fold_radius, "" otherwise (and when width or
// height is not positive). radius_of(dx, dy) is the model's radial
// coordinate of the pixel offset (dx, dy) from the principal point (cx, cy);
// it must be a norm of a linear map of (dx, dy) (|K^-1 (dx, dy)| for a focal
// matrix K, |A^-1 (dx, dy)| for an affine A). Such a norm is convex, so its
// maximum over the image is at a corner, and along the line from the
// principal point to that corner the fold sits at fold_radius / corner_radius
// of the corner's pixel distance.
template <typename RadiusOf>
std::string FoldInsideImageMessage(const char* model_name,
                                   double fold_angle_rad, double fold_radius,
                                   double cx, double cy, int width, int height,
                                   const RadiusOf& radius_of) {
  if (width <= 0 || height <= 0) return "";
  double corner_x = 0, corner_y = 0, corner_radius = -1;
  for (const double x : {0.0, static_cast<double>(width)}) {
    for (const double y : {0.0, static_cast<double>(height)}) {
      const double radius = radius_of(x - cx, y - cy);
      if (radius > corner_radius) {
        corner_radius = radius;
        corner_x = x;
        corner_y = y;
      }
    }
  }
  if (!(corner_radius > fold_radius)) return "";
  const double corner_px = std::hypot(corner_x - cx, corner_y - cy);
  return FoldMessage(model_name, fold_angle_rad,
                     corner_px * fold_radius / corner_radius, width, height,
                     "its corner (" + FormatFixed(corner_x, 0) + ", " +
                         FormatFixed(corner_y, 0) + ") is " +
                         FormatFixed(corner_px, 1) +
                         " px from the principal point (" + FormatFixed(cx, 1) +
                         ", " + FormatFixed(cy, 1) + ")");
}

}  // namespace internal
}  // namespace sphera
