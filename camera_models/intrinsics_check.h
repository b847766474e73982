// Checks of intrinsics read from another program's files (calibration and
// ground-truth importers): an image size and a pinhole matrix K as such
// files state them, before any camera is made of them. Each returns an
// empty string or what is wrong, for a message that names the file.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "camera_models/common.h"

namespace sphera {

// The longest image side accepted from a file: larger than any camera's
// sensor, small enough that an image of it can be allocated.
inline constexpr double kMaxImageSide = 100000;

// Why (width, height) is not an image size: not finite, not a whole
// number, below 1 or above kMaxImageSide.
inline std::string ImageSizeError(double width, double height) {
  for (const auto& [name, value] : {std::make_pair("width", width),
                                    std::make_pair("height", height)}) {
    const std::string text = internal::FormatNumber(value);
    if (!std::isfinite(value)) {
      return std::string("image ") + name + " " + text + " is not finite";
    }
    if (value != std::floor(value)) {
      return std::string("image ") + name + " " + text +
             " is not a whole number of pixels";
    }
    if (value < 1 || value > kMaxImageSide) {
      return std::string("image ") + name + " " + text + " is outside [1, " +
             internal::FormatNumber(kMaxImageSide) + "]";
    }
  }
  return "";
}

// Why K is not the intrinsic matrix of a pinhole camera of a width x height
// image, [fx 0 cx; 0 fy cy; 0 0 1]: entries not finite, a non-zero entry
// below the diagonal or K(2, 2) != 1 (not upper triangular and normalised),
// a skew (PINHOLE has none), a focal length <= 0, or a principal point
// outside the image. Comparisons allow 1e-9 of the matrix's scale.
inline std::string PinholeMatrixError(const Eigen::Matrix3d& K, double width,
                                      double height) {
  if (!K.allFinite()) return "K has an entry that is not finite";
  const double tolerance = 1e-9 * std::max(1.0, K.cwiseAbs().maxCoeff());
  const auto entry = [&K](int row, int col) {
    return "K(" + std::to_string(row + 1) + "," + std::to_string(col + 1) +
           ") = " + internal::FormatNumber(K(row, col));
  };
  for (const auto& [row, col] : {std::make_pair(1, 0), std::make_pair(2, 0),
                                 std::make_pair(2, 1)}) {
    if (std::abs(K(row, col)) > tolerance) {
      return "K is not upper triangular: " + entry(row, col);
    }
  }
  if (std::abs(K(2, 2) - 1) > 1e-9) {
    return "K is not normalised: " + entry(2, 2) + ", not 1";
  }
  if (std::abs(K(0, 1)) > tolerance) {
    return "K has a skew, " + entry(0, 1) + " (a pinhole camera has none)";
  }
  if (!(K(0, 0) > 0) || !(K(1, 1) > 0)) {
    return "focal lengths " + entry(0, 0) + ", " + entry(1, 1) +
           " must be positive";
  }
  if (K(0, 2) < 0 || K(0, 2) > width || K(1, 2) < 0 || K(1, 2) > height) {
    return "principal point (" + internal::FormatNumber(K(0, 2)) + ", " +
           internal::FormatNumber(K(1, 2)) + ") lies outside the " +
           internal::FormatNumber(width) + "x" +
           internal::FormatNumber(height) + " image";
  }
  return "";
}

}  // namespace sphera
