#include "colmap_ext/image/dual_fisheye_split.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <vector>

#include <opencv2/core.hpp>

namespace colmap {
namespace {

std::string CircleText(const ImageCircle& circle) {
  return "(cx, cy, r) = (" + ShortestDoubleText(circle.cx) + ", " +
         ShortestDoubleText(circle.cy) + ", " + ShortestDoubleText(circle.r) +
         ")";
}

std::string SizeText(const cv::Size& size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

// The part of RAW that is lens LENS (0: left half, 1: right half).
cv::Mat LensRegion(const cv::Mat& raw, int lens) {
  const cv::Size lens_size = LensImageSize(raw.size());
  return raw(
      cv::Rect(lens * lens_size.width, 0, lens_size.width, lens_size.height));
}

// Where the bright pixels of each row of BRIGHT (CV_8UC1) begin and end, as
// points on the pixel edge between black and bright, in the coordinates of
// BRIGHT (or, with TRANSPOSED, of the image BRIGHT is the transpose of).
// Runs that start or end on the image's border are not on the circle.
void AppendRowBoundaryPoints(const cv::Mat& bright,
                             bool transposed,
                             std::vector<cv::Point2d>* points) {
  for (int row = 0; row < bright.rows; ++row) {
    const uchar* pixels = bright.ptr<uchar>(row);
    int first = 0;
    while (first < bright.cols && pixels[first] == 0) {
      ++first;
    }
    if (first == bright.cols) {
      continue;
    }
    int last = bright.cols - 1;
    while (pixels[last] == 0) {
      --last;
    }
    const double along_row = row + 0.5;
    const auto add = [&](double edge) {
      points->push_back(transposed ? cv::Point2d(along_row, edge)
                                   : cv::Point2d(edge, along_row));
    };
    if (first != 0) {
      add(first);  // the left edge of the pixel
    }
    if (last != bright.cols - 1) {
      add(last + 1.0);  // the right edge of the pixel
    }
  }
}

// Algebraic (Kasa) least-squares circle through POINTS[i] for the i with
// USE[i]: minimises sum (x^2 + y^2 + D x + E y + F)^2, in coordinates
// relative to the points' mean for conditioning. False if degenerate.
bool FitCircle(const std::vector<cv::Point2d>& points,
               const std::vector<bool>& use,
               ImageCircle* circle) {
  cv::Point2d mean(0, 0);
  int count = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (use[i]) {
      mean += points[i];
      ++count;
    }
  }
  if (count < 3) {
    return false;
  }
  mean *= 1.0 / count;
  cv::Mat a(count, 3, CV_64F);
  cv::Mat b(count, 1, CV_64F);
  int row = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!use[i]) {
      continue;
    }
    const cv::Point2d p = points[i] - mean;
    a.at<double>(row, 0) = p.x;
    a.at<double>(row, 1) = p.y;
    a.at<double>(row, 2) = 1;
    b.at<double>(row, 0) = -(p.x * p.x + p.y * p.y);
    ++row;
  }
  cv::Mat solution;
  if (!cv::solve(a, b, solution, cv::DECOMP_SVD)) {
    return false;
  }
  const double cx = -solution.at<double>(0) / 2;
  const double cy = -solution.at<double>(1) / 2;
  const double r_squared = cx * cx + cy * cy - solution.at<double>(2);
  if (!(r_squared > 0) || !std::isfinite(r_squared)) {
    return false;
  }
  *circle = {cx + mean.x, cy + mean.y, std::sqrt(r_squared)};
  return true;
}

// The median of VALUES (not empty): the middle one, or the mean of the two
// middle ones.
double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

// With CIRCLE's centre fixed, the radius that best separates the bright
// pixels of BRIGHT (inside) from the black ones (outside) by the pixel-centre
// rule, among the pixels within 2 px of CIRCLE: the fewest misclassified
// pixels, the radius half way (in r^2) between the pixel centres that bound
// that choice. A hard-edged disc's own mask is then reproduced when the
// centre is close enough; kept within 1 px of CIRCLE's radius.
double BestSeparatingRadius(const cv::Mat& bright, const ImageCircle& circle) {
  constexpr double kBandPx = 2.0;
  const double inner = std::max(0.0, circle.r - kBandPx);
  const double outer = circle.r + kBandPx;
  std::vector<std::pair<double, bool>> band;  // (squared distance, bright)
  const int y_begin = std::max(0, static_cast<int>(circle.cy - outer));
  const int y_end =
      std::min(bright.rows, static_cast<int>(circle.cy + outer) + 1);
  const int x_begin = std::max(0, static_cast<int>(circle.cx - outer));
  const int x_end =
      std::min(bright.cols, static_cast<int>(circle.cx + outer) + 1);
  for (int y = y_begin; y < y_end; ++y) {
    const double dy = y + 0.5 - circle.cy;
    const double dy_squared = dy * dy;
    const uchar* row = bright.ptr<uchar>(y);
    for (int x = x_begin; x < x_end; ++x) {
      const double dx = x + 0.5 - circle.cx;
      const double dx_squared = dx * dx;
      const double d_squared = dx_squared + dy_squared;
      if (d_squared >= inner * inner && d_squared <= outer * outer) {
        band.emplace_back(d_squared, row[x] != 0);
      }
    }
  }
  if (band.empty()) {
    return circle.r;
  }
  std::sort(band.begin(), band.end());
  // Errors of a radius below every pixel of the band: its bright pixels.
  long errors = std::count_if(
      band.begin(), band.end(), [](const auto& pixel) { return pixel.second; });
  long best_errors = errors;
  double best_r_squared = inner * inner;
  for (size_t i = 0; i < band.size(); ++i) {
    errors += band[i].second ? -1 : 1;  // pixel i is now inside
    // Only between distinct distances; ties move together.
    if (i + 1 < band.size() && band[i + 1].first == band[i].first) {
      continue;
    }
    if (errors < best_errors) {
      best_errors = errors;
      best_r_squared = i + 1 < band.size()
                           ? (band[i].first + band[i + 1].first) / 2
                           : band[i].first;
    }
  }
  const double r = std::sqrt(best_r_squared);
  return std::abs(r - circle.r) <= 1.0 ? r : circle.r;
}

}  // namespace

std::string DualFisheyeLayoutError(const cv::Mat& raw) {
  if (raw.empty()) {
    return "empty image";
  }
  if (raw.depth() != CV_8U && raw.depth() != CV_16U) {
    return "not an 8-bit or 16-bit image";
  }
  if (raw.channels() > 4) {
    return std::to_string(raw.channels()) + " channels (at most 4)";
  }
  if (raw.cols % 2 != 0) {
    return "odd width " + std::to_string(raw.cols) + " (" +
           SizeText(raw.size()) +
           "): a dual-fisheye frame is two lens images side by side, of even "
           "width";
  }
  return "";
}

cv::Size LensImageSize(const cv::Size& raw_size) {
  return cv::Size(raw_size.width / 2, raw_size.height);
}

std::string ImageCircleError(const ImageCircle& circle,
                             const cv::Size& lens_size) {
  if (!std::isfinite(circle.cx) || !std::isfinite(circle.cy) ||
      !std::isfinite(circle.r)) {
    return "image circle " + CircleText(circle) + " is not finite";
  }
  if (circle.r <= 0) {
    return "image circle " + CircleText(circle) + " has radius <= 0";
  }
  const double width = lens_size.width;
  const double height = lens_size.height;
  const std::pair<const char*, double> overshoots[] = {
      {"left", circle.r - circle.cx},
      {"right", circle.cx + circle.r - width},
      {"top", circle.r - circle.cy},
      {"bottom", circle.cy + circle.r - height}};
  for (const auto& [side, overshoot] : overshoots) {
    if (overshoot > 0) {
      return "image circle " + CircleText(circle) + " goes outside the " +
             SizeText(lens_size) + " lens image (by " +
             ShortestDoubleText(overshoot) + " px on the " + side + ")";
    }
  }
  return "";
}

ImageCircle ClampDetectedImageCircle(const ImageCircle& circle,
                                     const cv::Size& lens_size) {
  const double room = std::min({circle.cx,
                                lens_size.width - circle.cx,
                                circle.cy,
                                lens_size.height - circle.cy});
  const double overshoot = circle.r - room;
  if (overshoot > 0 && overshoot <= kMaxDetectedCircleOvershootPx && room > 0) {
    return {circle.cx, circle.cy, room};
  }
  return circle;
}

cv::Mat ImageCircleMask(const cv::Size& size, const ImageCircle& circle) {
  // The squares are stored before they are summed, so that the compiler
  // cannot fuse a multiply and an add (FMA) and round differently from the
  // stated rule, which other programs (the renderer) evaluate as written.
  std::vector<double> dx_squared(size.width);
  for (int x = 0; x < size.width; ++x) {
    const double dx = x + 0.5 - circle.cx;
    dx_squared[x] = dx * dx;
  }
  const double r_squared = circle.r * circle.r;
  cv::Mat mask(size, CV_8UC1);
  for (int y = 0; y < size.height; ++y) {
    const double dy = y + 0.5 - circle.cy;
    const double dy_squared = dy * dy;
    uchar* row = mask.ptr<uchar>(y);
    for (int x = 0; x < size.width; ++x) {
      row[x] = dx_squared[x] + dy_squared <= r_squared ? 255 : 0;
    }
  }
  return mask;
}

cv::Mat BrightPixelMask(const cv::Mat& image, int black_level) {
  std::vector<cv::Mat> channels;
  cv::split(image, channels);
  // Gray (+ alpha): the gray channel; colour (+ alpha): the colour channels.
  const int num_colour_channels = image.channels() <= 2 ? 1 : 3;
  cv::Mat intensity = channels[0];
  for (int c = 1; c < num_colour_channels; ++c) {
    cv::max(intensity, channels[c], intensity);
  }
  const double level =
      image.depth() == CV_16U ? black_level * 257.0 : black_level;
  cv::Mat bright;
  cv::compare(intensity, level, bright, cv::CMP_GT);
  return bright;
}

double BrightFractionOutsideCircles(const cv::Mat& raw,
                                    const std::array<ImageCircle, 2>& circles,
                                    int black_level) {
  double num_outside = 0;
  double num_bright_outside = 0;
  for (int lens = 0; lens < 2; ++lens) {
    const cv::Mat region = LensRegion(raw, lens);
    cv::Mat outside;
    cv::bitwise_not(ImageCircleMask(region.size(), circles[lens]), outside);
    cv::Mat bright_outside;
    cv::bitwise_and(
        BrightPixelMask(region, black_level), outside, bright_outside);
    num_outside += cv::countNonZero(outside);
    num_bright_outside += cv::countNonZero(bright_outside);
  }
  return num_outside > 0 ? num_bright_outside / num_outside : 0.0;
}

std::string DualFisheyeFrameError(const cv::Mat& raw,
                                  const std::array<ImageCircle, 2>& circles,
                                  int black_level) {
  const std::string layout_error = DualFisheyeLayoutError(raw);
  if (!layout_error.empty()) {
    return layout_error;
  }
  const double fraction =
      BrightFractionOutsideCircles(raw, circles, black_level);
  if (fraction > kMaxBrightFractionOutsideCircles) {
    char text[256];
    std::snprintf(text,
                  sizeof(text),
                  "%.1f%% of the pixels outside the two image circles are "
                  "brighter than the black level %d (at most %.0f%% may be): "
                  "not a dual-fisheye frame (a normal photo or an "
                  "equirectangular panorama?)",
                  100 * fraction,
                  black_level,
                  100 * kMaxBrightFractionOutsideCircles);
    return text;
  }
  return "";
}

std::string DetectImageCircle(const cv::Mat& lens_image,
                              int black_level,
                              ImageCircle* circle) {
  const cv::Mat bright = BrightPixelMask(lens_image, black_level);
  std::vector<cv::Point2d> points;
  AppendRowBoundaryPoints(bright, /*transposed=*/false, &points);
  cv::Mat bright_transposed;
  cv::transpose(bright, bright_transposed);
  AppendRowBoundaryPoints(bright_transposed, /*transposed=*/true, &points);

  constexpr size_t kMinPoints = 16;
  if (points.size() < kMinPoints) {
    return "no image circle found: " + std::to_string(points.size()) +
           " points where bright pixels (above the black level " +
           std::to_string(black_level) +
           ") meet black ones inside the image (all black, or bright up to "
           "the image's edges?)";
  }

  std::vector<bool> inliers(points.size(), true);
  ImageCircle fit;
  std::vector<double> distances(points.size());
  constexpr int kMaxIterations = 20;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    if (!FitCircle(points, inliers, &fit)) {
      return "no image circle found: the boundary of the bright pixels is "
             "not a circle";
    }
    for (size_t i = 0; i < points.size(); ++i) {
      distances[i] = std::abs(
          std::hypot(points[i].x - fit.cx, points[i].y - fit.cy) - fit.r);
    }
    const double threshold = std::max(1.5, 3 * Median(distances));
    std::vector<bool> next(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      next[i] = distances[i] <= threshold;
    }
    if (next == inliers) {
      break;
    }
    inliers = std::move(next);
  }

  // The inliers must be most of the points, close to the circle (the
  // median distance at most max(1 px, 1% of r); a hard-edged disc gives
  // about 0.25 px) and go round its centre (at least 5 of 8 sectors of 45
  // degrees), not lie on one side of it.
  std::vector<double> inlier_distances;
  bool sectors[8] = {};
  for (size_t i = 0; i < points.size(); ++i) {
    if (!inliers[i]) {
      continue;
    }
    inlier_distances.push_back(distances[i]);
    const double angle =
        std::atan2(points[i].y - fit.cy, points[i].x - fit.cx);  // -pi..pi
    const int sector = static_cast<int>((angle + CV_PI) / (CV_PI / 4));
    sectors[std::clamp(sector, 0, 7)] = true;
  }
  const size_t num_inliers = inlier_distances.size();
  const int num_sectors =
      static_cast<int>(std::count(sectors, sectors + 8, true));
  const double median_distance =
      num_inliers > 0 ? Median(inlier_distances) : 0.0;
  if (num_inliers < kMinPoints || 2 * num_inliers < points.size() ||
      median_distance > std::max(1.0, 0.01 * fit.r) || num_sectors < 5) {
    return "no image circle found: of " + std::to_string(points.size()) +
           " points where bright pixels meet black ones, " +
           std::to_string(num_inliers) + " lie near the circle " +
           CircleText(fit) + " (median distance " +
           ShortestDoubleText(std::round(median_distance * 100) / 100) +
           " px), in " + std::to_string(num_sectors) +
           " of 8 directions from its centre";
  }
  fit.r = BestSeparatingRadius(bright, fit);
  *circle = fit;
  return "";
}

ImageCircle MedianImageCircle(const std::vector<ImageCircle>& circles) {
  if (circles.empty()) {
    throw std::invalid_argument("the median of no image circles");
  }
  std::vector<double> cx, cy, r;
  for (const ImageCircle& circle : circles) {
    cx.push_back(circle.cx);
    cy.push_back(circle.cy);
    r.push_back(circle.r);
  }
  return {Median(cx), Median(cy), Median(r)};
}

std::array<LensImage, 2> SplitDualFisheye(
    const cv::Mat& raw, const std::array<ImageCircle, 2>& circles) {
  const std::string layout_error = DualFisheyeLayoutError(raw);
  if (!layout_error.empty()) {
    throw std::invalid_argument(layout_error);
  }
  std::array<LensImage, 2> lenses;
  for (int lens = 0; lens < 2; ++lens) {
    const cv::Mat region = LensRegion(raw, lens);
    const std::string circle_error =
        ImageCircleError(circles[lens], region.size());
    if (!circle_error.empty()) {
      throw std::invalid_argument("lens " + std::to_string(lens) + ": " +
                                  circle_error);
    }
    lenses[lens].mask = ImageCircleMask(region.size(), circles[lens]);
    lenses[lens].image = region.clone();
    lenses[lens].image.setTo(cv::Scalar::all(0), lenses[lens].mask == 0);
  }
  return lenses;
}

std::string ParseImageCircles(const std::string& text,
                              std::array<ImageCircle, 2>* circles) {
  const std::string expected =
      "expected two circles \"cx,cy,r;cx,cy,r\" (lens0;lens1), got \"" + text +
      "\"";
  std::vector<double> values;
  size_t num_circles = 0;
  size_t begin = 0;
  while (begin <= text.size()) {
    const size_t end = std::min(text.find(';', begin), text.size());
    const std::string circle_text = text.substr(begin, end - begin);
    ++num_circles;
    size_t value_begin = 0;
    size_t num_values = 0;
    while (value_begin <= circle_text.size()) {
      const size_t value_end =
          std::min(circle_text.find(',', value_begin), circle_text.size());
      const std::string value_text =
          circle_text.substr(value_begin, value_end - value_begin);
      const char* first = value_text.c_str();
      char* last = nullptr;
      const double value = std::strtod(first, &last);
      // strtod skips leading blanks; allow trailing ones too.
      while (last != nullptr && (*last == ' ' || *last == '\t')) {
        ++last;
      }
      if (last == first || *last != '\0' || !std::isfinite(value)) {
        return expected + ": \"" + value_text + "\" is not a number";
      }
      values.push_back(value);
      ++num_values;
      value_begin = value_end + 1;
    }
    if (num_values != 3) {
      return expected;
    }
    begin = end + 1;
  }
  if (num_circles != 2) {
    return expected;
  }
  for (int lens = 0; lens < 2; ++lens) {
    (*circles)[lens] = {
        values[3 * lens], values[3 * lens + 1], values[3 * lens + 2]};
  }
  return "";
}

std::string ShortestDoubleText(double value) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

}  // namespace colmap
