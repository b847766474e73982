// Parameter checks for models whose projection can fold: a fitted polynomial
// (Kannala-Brandt, OCamCalib) is monotone only up to some angle, and beyond it
// two rays share a pixel. Such parameters are refused when the lens's image
// circle reaches past the fold (pixels there have no ray of the model); a
// fold outside it is harmless and accepted.
#pragma once

#include <algorithm>
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

// The image circle that a width x height image can hold about the principal
// point (cx, cy): the circle through the farthest of the four edge
// midpoints. A lens's pixels lie inside it: a fisheye's image circle inside
// the frame, or cropped by two edges of it (8-lens cameras keep 68% of the
// circle's height), a normal lens filling the frame to its edges. Only the
// corners beyond it are left out, which a fisheye's circle does not reach;
// a fold there (a polynomial fitted to the circle turning over past its
// rim) leaves every pixel of the lens its ray.
inline double ImageCircleRadius(double cx, double cy, int width, int height) {
  return std::max(std::max(cx, width - cx), std::max(cy, height - cy));
}

// "<MODEL>: projection folds at 97.3° (r = 812.4 px), inside the image
// circle of the 1600x1088 image (radius 800.0 px about the principal point
// (800.0, 544.0))<where>".
inline std::string FoldMessage(const char* model_name, double fold_angle_rad,
                               double fold_radius_px, double cx, double cy,
                               int width, int height,
                               const std::string& where) {
  constexpr double kRadToDeg = 57.29577951308232;
  return std::string(model_name) + ": projection folds at " +
         FormatFixed(fold_angle_rad * kRadToDeg, 1) + "° (r = " +
         FormatFixed(fold_radius_px, 1) + " px), inside the image circle of " +
         "the " + std::to_string(width) + "x" + std::to_string(height) +
         " image (radius " +
         FormatFixed(ImageCircleRadius(cx, cy, width, height), 1) +
         " px about the principal point (" + FormatFixed(cx, 1) + ", " +
         FormatFixed(cy, 1) + "))" + where;
}

// The fold message if the image circle (ImageCircleRadius) holds a pixel
// beyond a fold at radial coordinate fold_radius, "" otherwise (and when
// width or height is not positive). radius_of(dx, dy) is the model's radial
// coordinate of the pixel offset (dx, dy) from the principal point (cx, cy);
// it must be a norm of a linear map of (dx, dy) (|K^-1 (dx, dy)| for a focal
// matrix K, |A^-1 (dx, dy)| for an affine A), so along each direction the
// fold sits at fold_radius / radius_of(unit direction) pixels. The circle
// is searched on 720 directions, which hold the axes of a diagonal K.
template <typename RadiusOf>
std::string FoldInsideImageMessage(const char* model_name,
                                   double fold_angle_rad, double fold_radius,
                                   double cx, double cy, int width, int height,
                                   const RadiusOf& radius_of) {
  if (width <= 0 || height <= 0) return "";
  const double circle_px = ImageCircleRadius(cx, cy, width, height);
  constexpr int kDirections = 720;
  constexpr double kPi = 3.14159265358979323846;
  double max_radius = -1, max_x = 0, max_y = 0;
  for (int i = 0; i < kDirections; ++i) {
    const double phi = 2 * kPi * i / kDirections;
    const double dx = circle_px * std::cos(phi), dy = circle_px * std::sin(phi);
    const double radius = radius_of(dx, dy);
    if (radius > max_radius) {
      max_radius = radius;
      max_x = cx + dx;
      max_y = cy + dy;
    }
  }
  if (!(max_radius > fold_radius)) return "";
  const double fold_px = circle_px * fold_radius / max_radius;
  return FoldMessage(model_name, fold_angle_rad, fold_px, cx, cy, width,
                     height,
                     ": the circle reaches past it towards (" +
                         FormatFixed(max_x, 0) + ", " + FormatFixed(max_y, 0) +
                         ")");
}

}  // namespace internal
}  // namespace sphera
