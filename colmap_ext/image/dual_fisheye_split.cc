#include "colmap_ext/image/dual_fisheye_split.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace colmap {
namespace {

// Outside a lens's image circle is dark: at most this fraction of the
// intensity just inside it. Not black: a housing in sunlight, flare and
// the lens's own glow reach 40-60% of a dim picture at the rim.
constexpr double kMaxDarkRatio = 0.6;

std::string CircleText(const ImageCircle& circle) {
  return "(cx, cy, r) = (" + ShortestDoubleText(circle.cx) + ", " +
         ShortestDoubleText(circle.cy) + ", " + ShortestDoubleText(circle.r) +
         ")";
}

std::string SizeText(const cv::Size& size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
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

// The circle bounding the pixels of LENS_IMAGE brighter than BLACK_LEVEL.
// Boundary points are where each row and each column enters and leaves the
// bright pixels (on the pixel edge between the last black and the first
// bright pixel, so a hard-edged disc gives points within half a pixel of
// its circle); points on the image's border are left out. A circle is
// fitted to them by Kasa least squares, refitted to the points within
// max(1.5 px, 3 x the median distance) of the last fit until the inliers no
// longer change; last, with the centre fixed, the radius is moved (by at
// most 1 px) to where it misclassifies the fewest pixels within 2 px of the
// circle. Exact for a disc on black; a grey housing ring around the circle
// makes it the housing's circle, which is why DetectImageCircle finds the
// circle by its edge and uses this only where the two agree.
std::string DetectBrightDisc(const cv::Mat& lens_image,
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

// The largest colour channel of IMAGE (the alpha channel, a 4th, left out),
// of IMAGE's depth.
cv::Mat MaxColourChannel(const cv::Mat& image) {
  std::vector<cv::Mat> channels;
  cv::split(image, channels);
  // Gray (+ alpha): the gray channel; colour (+ alpha): the colour channels.
  const int num_colour_channels = image.channels() <= 2 ? 1 : 3;
  cv::Mat intensity = channels[0].clone();
  for (int c = 1; c < num_colour_channels; ++c) {
    cv::max(intensity, channels[c], intensity);
  }
  return intensity;
}

// The intensity of IMAGE as CV_32F in [0, 1].
cv::Mat NormalizedIntensity(const cv::Mat& image) {
  cv::Mat intensity;
  MaxColourChannel(image).convertTo(
      intensity, CV_32F, image.depth() == CV_16U ? 1.0 / 65535 : 1.0 / 255);
  return intensity;
}

// INTENSITY (CV_32F) at the image point (x, y) (pixel corners at integers,
// so pixel (i, j)'s value is at (i + 0.5, j + 0.5)), bilinear; points within
// half a pixel of the border take the border pixels' values. False outside
// [0, W] x [0, H].
bool Sample(const cv::Mat& intensity, double x, double y, float* value) {
  if (!(x >= 0 && y >= 0 && x <= intensity.cols && y <= intensity.rows)) {
    return false;
  }
  const double u = std::clamp(x - 0.5, 0.0, intensity.cols - 1.0);
  const double v = std::clamp(y - 0.5, 0.0, intensity.rows - 1.0);
  const int x0 = std::min(static_cast<int>(u), std::max(0, intensity.cols - 2));
  const int y0 = std::min(static_cast<int>(v), std::max(0, intensity.rows - 2));
  const int x1 = std::min(x0 + 1, intensity.cols - 1);
  const int y1 = std::min(y0 + 1, intensity.rows - 1);
  const double fx = u - x0;
  const double fy = v - y0;
  const float* row0 = intensity.ptr<float>(y0);
  const float* row1 = intensity.ptr<float>(y1);
  *value = static_cast<float>((1 - fy) * ((1 - fx) * row0[x0] + fx * row0[x1]) +
                              fy * ((1 - fx) * row1[x0] + fx * row1[x1]));
  return true;
}

// INTENSITY along the ray from CENTRE in direction ANGLE at distances
// R_BEGIN, R_BEGIN + 1, ... up to R_END or until the ray leaves the image.
std::vector<float> RayProfile(const cv::Mat& intensity,
                              const cv::Point2d& centre,
                              double angle,
                              double r_begin,
                              double r_end) {
  std::vector<float> profile;
  const double dx = std::cos(angle);
  const double dy = std::sin(angle);
  for (double r = r_begin; r <= r_end; r += 1.0) {
    float value;
    if (!Sample(intensity, centre.x + r * dx, centre.y + r * dy, &value)) {
      break;
    }
    profile.push_back(value);
  }
  return profile;
}

// A place on a ray where the picture may end: its distance along the ray
// and how much darker it is after than before.
struct EdgeCandidate {
  double distance = 0;
  double strength = 0;
};

// The picture-to-dark edges of PROFILE (samples 1 px apart, the first at
// distance R_BEGIN): local maxima of the step
//   S(k) = mean(P[k - w .. k - 1]) - mean(P[k + 1 .. k + w])
// of at least kMinEdgeStep whose after-mean is at most kMaxDarkRatio of the
// before-mean, located by a parabola through S(k - 1), S(k), S(k + 1); the
// MAX_CANDIDATES strongest.
constexpr double kMinEdgeStep = 0.03;

std::vector<EdgeCandidate> EdgeCandidates(const std::vector<float>& profile,
                                          double r_begin,
                                          int window,
                                          size_t max_candidates) {
  const int n = static_cast<int>(profile.size());
  std::vector<EdgeCandidate> candidates;
  if (n < 2 * window + 3) {
    return candidates;
  }
  std::vector<double> sums(n + 1, 0.0);
  for (int k = 0; k < n; ++k) {
    sums[k + 1] = sums[k] + profile[k];
  }
  std::vector<double> step(n, 0.0);
  std::vector<bool> dark_after(n, false);
  for (int k = window; k + window < n; ++k) {
    const double before = (sums[k] - sums[k - window]) / window;
    const double after = (sums[k + 1 + window] - sums[k + 1]) / window;
    step[k] = before - after;
    dark_after[k] = after <= kMaxDarkRatio * before;
  }
  for (int k = window + 1; k + window + 1 < n; ++k) {
    if (!dark_after[k] || step[k] < kMinEdgeStep || step[k] <= step[k - 1] ||
        step[k] < step[k + 1]) {
      continue;
    }
    const double curvature = step[k - 1] - 2 * step[k] + step[k + 1];
    const double offset =
        curvature < 0
            ? std::clamp(
                  0.5 * (step[k - 1] - step[k + 1]) / curvature, -0.5, 0.5)
            : 0.0;
    candidates.push_back({r_begin + k + offset, step[k]});
  }
  std::sort(candidates.begin(),
            candidates.end(),
            [](const EdgeCandidate& a, const EdgeCandidate& b) {
              return a.strength > b.strength;
            });
  if (candidates.size() > max_candidates) {
    candidates.resize(max_candidates);
  }
  return candidates;
}

// An edge candidate as an image point, with the ray it lies on.
struct EdgePoint {
  cv::Point2d point;
  double strength = 0;
  int ray = 0;
};

constexpr int kNumRays = 720;

double RayAngle(int ray) { return 2 * CV_PI * ray / kNumRays; }

// The edge candidates of rays from CENTRE between distances R_BEGIN and
// R_END, MAX_PER_RAY a ray.
std::vector<EdgePoint> EdgePointsAlongRays(const cv::Mat& intensity,
                                           const cv::Point2d& centre,
                                           double r_begin,
                                           double r_end,
                                           int window,
                                           size_t max_per_ray) {
  std::vector<EdgePoint> points;
  for (int ray = 0; ray < kNumRays; ++ray) {
    const double angle = RayAngle(ray);
    const std::vector<float> profile =
        RayProfile(intensity, centre, angle, r_begin, r_end);
    for (const EdgeCandidate& candidate :
         EdgeCandidates(profile, r_begin, window, max_per_ray)) {
      points.push_back(
          {centre + candidate.distance *
                        cv::Point2d(std::cos(angle), std::sin(angle)),
           candidate.strength,
           ray});
    }
  }
  return points;
}

// The circle through A, B and C; false when they are (nearly) collinear.
bool CircleThrough(const cv::Point2d& a,
                   const cv::Point2d& b,
                   const cv::Point2d& c,
                   ImageCircle* circle) {
  const cv::Point2d ab = b - a;
  const cv::Point2d ac = c - a;
  const double d = 2 * (ab.x * ac.y - ab.y * ac.x);
  const double scale = ab.dot(ab) + ac.dot(ac);
  if (!(std::abs(d) > 1e-9 * scale)) {
    return false;
  }
  const double ab2 = ab.dot(ab);
  const double ac2 = ac.dot(ac);
  const cv::Point2d offset((ac.y * ab2 - ab.y * ac2) / d,
                           (ab.x * ac2 - ac.x * ab2) / d);
  *circle = {a.x + offset.x, a.y + offset.y, std::hypot(offset.x, offset.y)};
  return true;
}

double DistanceToCircle(const cv::Point2d& point, const ImageCircle& circle) {
  return std::abs(std::hypot(point.x - circle.cx, point.y - circle.cy) -
                  circle.r);
}

// How far an edge point may be from the image circle and still be on it:
// a real lens's edge is a soft fall-off whose steepest point moves with the
// brightness of the picture at the rim (several pixels further out next to
// a bright sky than next to grass), so 1% of the radius, at least 1.5 px.
double InlierTolerance(const ImageCircle& circle) {
  return std::max(1.5, 0.01 * circle.r);
}

// Whether CIRCLE may be a lens's image circle in an image of SIZE (a RANSAC
// hypothesis): a camera centres each lens's circle in its image, so the
// centre is within 20% of the smaller side of the image's centre, and the
// radius between 25% of the smaller side and the diagonal.
bool PlausibleCircle(const ImageCircle& circle, const cv::Size& size) {
  const double min_side = std::min(size.width, size.height);
  return std::hypot(circle.cx - size.width / 2.0,
                    circle.cy - size.height / 2.0) <= 0.2 * min_side &&
         circle.r >= 0.25 * min_side &&
         circle.r <= std::hypot(size.width, size.height);
}

// The circle among POINTS with the largest score, the summed strength of
// the strongest point within InlierTolerance of it on each ray (RANSAC over
// triples of points of different rays, a fixed seed: the same image gives
// the same circle). False when no triple gives a plausible circle.
bool StrongestCircle(const std::vector<EdgePoint>& points,
                     const cv::Size& size,
                     ImageCircle* best) {
  constexpr int kNumIterations = 6000;
  std::mt19937 random(12345);
  std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
  double best_score = 0;
  std::vector<double> ray_strength(kNumRays);
  // The three points at least 60 degrees apart round the image's centre: a
  // triple bunched on one arc defines a circle poorly.
  const auto apart = [](const EdgePoint& a, const EdgePoint& b) {
    const int difference = std::abs(a.ray - b.ray);
    return std::min(difference, kNumRays - difference) >= kNumRays / 6;
  };
  for (int iteration = 0; iteration < kNumIterations; ++iteration) {
    const EdgePoint& a = points[pick(random)];
    const EdgePoint& b = points[pick(random)];
    const EdgePoint& c = points[pick(random)];
    if (!apart(a, b) || !apart(a, c) || !apart(b, c)) {
      continue;
    }
    ImageCircle circle;
    if (!CircleThrough(a.point, b.point, c.point, &circle) ||
        !PlausibleCircle(circle, size)) {
      continue;
    }
    const double tolerance = InlierTolerance(circle);
    std::fill(ray_strength.begin(), ray_strength.end(), 0.0);
    for (const EdgePoint& point : points) {
      if (DistanceToCircle(point.point, circle) <= tolerance) {
        ray_strength[point.ray] =
            std::max(ray_strength[point.ray], point.strength);
      }
    }
    const double score =
        std::accumulate(ray_strength.begin(), ray_strength.end(), 0.0);
    if (score > best_score) {
      best_score = score;
      *best = circle;
    }
  }
  return best_score > 0;
}

// Kasa fits to POINTS, each refitted to the points within InlierTolerance
// of the last fit, starting from START, until the inliers no longer change.
// Sets *INLIERS. False when too few points remain.
bool RefitToInliers(const std::vector<cv::Point2d>& points,
                    const ImageCircle& start,
                    ImageCircle* circle,
                    std::vector<bool>* inliers) {
  std::vector<bool> use(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    use[i] = DistanceToCircle(points[i], start) <= InlierTolerance(start);
  }
  ImageCircle fit = start;
  constexpr int kMaxIterations = 20;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    if (!FitCircle(points, use, &fit)) {
      return false;
    }
    std::vector<bool> next(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      next[i] = DistanceToCircle(points[i], fit) <= InlierTolerance(fit);
    }
    if (next == use) {
      break;
    }
    use = std::move(next);
  }
  *circle = fit;
  *inliers = std::move(use);
  return true;
}

// The window of the edge filter for an image of SIZE.
int EdgeWindow(const cv::Size& size) {
  return std::max(
      2,
      static_cast<int>(std::lround(0.01 * std::min(size.width, size.height))));
}

// The circle found by its edge in INTENSITY (blurred); "" or why none.
std::string DetectCircleEdge(const cv::Mat& intensity, ImageCircle* circle) {
  const cv::Size size = intensity.size();
  const int window = EdgeWindow(size);
  const cv::Point2d image_centre(size.width / 2.0, size.height / 2.0);
  const double min_side = std::min(size.width, size.height);
  const double diagonal = std::hypot(size.width, size.height);
  const std::vector<EdgePoint> candidates = EdgePointsAlongRays(
      intensity, image_centre, 0.1 * min_side, diagonal, window, 4);
  constexpr size_t kMinPoints = 16;
  ImageCircle fit;
  if (candidates.size() < kMinPoints ||
      !StrongestCircle(candidates, size, &fit)) {
    return "no image circle found: " + std::to_string(candidates.size()) +
           " places where the picture turns dark along 720 rays from the "
           "image's centre, and no circle through them";
  }
  std::vector<cv::Point2d> points;
  for (const EdgePoint& candidate : candidates) {
    points.push_back(candidate.point);
  }
  std::vector<bool> inliers;
  if (!RefitToInliers(points, fit, &fit, &inliers)) {
    return "no image circle found: the edges along rays from the image's "
           "centre are not on a circle";
  }

  // Rays from the circle's own centre cross its edge at right angles: the
  // strongest edge within a band around the circle, a ray.
  std::vector<EdgePoint> refined;
  for (int round = 0; round < 2; ++round) {
    const double band = std::max(3.0 * window, 0.03 * fit.r);
    refined = EdgePointsAlongRays(intensity,
                                  cv::Point2d(fit.cx, fit.cy),
                                  std::max(0.0, fit.r - band),
                                  fit.r + band,
                                  window,
                                  1);
    points.clear();
    for (const EdgePoint& point : refined) {
      points.push_back(point.point);
    }
    if (points.size() < kMinPoints ||
        !RefitToInliers(points, fit, &fit, &inliers)) {
      return "no image circle found: too few edges near the circle " +
             CircleText(fit);
    }
  }

  // The inliers must cover most of the circle's rim that is in the image:
  // half of the rays that cross it inside the image (with room for the
  // edge filter's window), and 3/4 of the 45-degree sectors those rays are
  // in.
  const double margin = window + 1.0;
  int num_visible = 0;
  bool visible_sectors[8] = {};
  std::vector<bool> visible_rays(kNumRays, false);
  for (int ray = 0; ray < kNumRays; ++ray) {
    const double angle = RayAngle(ray);
    const double x = fit.cx + fit.r * std::cos(angle);
    const double y = fit.cy + fit.r * std::sin(angle);
    if (x >= margin && y >= margin && x <= size.width - margin &&
        y <= size.height - margin) {
      visible_rays[ray] = true;
      ++num_visible;
      visible_sectors[ray * 8 / kNumRays] = true;
    }
  }
  std::vector<bool> inlier_rays(kNumRays, false);
  bool inlier_sectors[8] = {};
  for (size_t i = 0; i < refined.size(); ++i) {
    if (inliers[i] && visible_rays[refined[i].ray]) {
      inlier_rays[refined[i].ray] = true;
      inlier_sectors[refined[i].ray * 8 / kNumRays] = true;
    }
  }
  const int num_inlier_rays = static_cast<int>(
      std::count(inlier_rays.begin(), inlier_rays.end(), true));
  const int num_visible_sectors =
      static_cast<int>(std::count(visible_sectors, visible_sectors + 8, true));
  const int num_inlier_sectors =
      static_cast<int>(std::count(inlier_sectors, inlier_sectors + 8, true));
  if (num_inlier_rays < static_cast<int>(kMinPoints) ||
      2 * num_inlier_rays < num_visible ||
      4 * num_inlier_sectors < 3 * num_visible_sectors ||
      num_inlier_sectors < 3) {
    return "no image circle found: the best circle " + CircleText(fit) +
           " has an edge on " + std::to_string(num_inlier_rays) + " of the " +
           std::to_string(num_visible) +
           " rays from its centre that cross it inside the image, in " +
           std::to_string(num_inlier_sectors) + " of " +
           std::to_string(num_visible_sectors) + " directions";
  }
  *circle = fit;
  return "";
}

// The part of CIRCLE inside an image of SIZE, as a fraction of the image:
// the pixels whose centres are inside, counted a row at a time.
double CoveredFraction(const ImageCircle& circle, const cv::Size& size) {
  double num_inside = 0;
  for (int y = 0; y < size.height; ++y) {
    const double dy = y + 0.5 - circle.cy;
    const double half_squared = circle.r * circle.r - dy * dy;
    if (half_squared < 0) {
      continue;
    }
    const double half = std::sqrt(half_squared);
    // Columns x with |x + 0.5 - cx| <= half.
    const double first = std::max(0.0, std::ceil(circle.cx - half - 0.5));
    const double last =
        std::min(size.width - 1.0, std::floor(circle.cx + half - 0.5));
    num_inside += std::max(0.0, last - first + 1);
  }
  return num_inside / (static_cast<double>(size.width) * size.height);
}

}  // namespace

std::string LensImageError(const cv::Mat& image) {
  if (image.empty()) {
    return "empty image";
  }
  if (image.depth() != CV_8U && image.depth() != CV_16U) {
    return "not an 8-bit or 16-bit image";
  }
  if (image.channels() > 4) {
    return std::to_string(image.channels()) + " channels (at most 4)";
  }
  return "";
}

std::string DualFisheyeLayoutError(const cv::Mat& raw) {
  if (const std::string error = LensImageError(raw); !error.empty()) {
    return error;
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

std::array<cv::Mat, 2> LensImagesOfRawFrame(const cv::Mat& raw) {
  const cv::Size lens_size = LensImageSize(raw.size());
  return {raw(cv::Rect(0, 0, lens_size.width, lens_size.height)),
          raw(cv::Rect(lens_size.width, 0, lens_size.width, lens_size.height))};
}

std::string ImageCircleError(const ImageCircle& circle,
                             const cv::Size& lens_size) {
  const std::string what = "image circle " + CircleText(circle);
  if (!std::isfinite(circle.cx) || !std::isfinite(circle.cy) ||
      !std::isfinite(circle.r)) {
    return what + " is not finite";
  }
  if (circle.r <= 0) {
    return what + " has radius <= 0";
  }
  if (circle.cx < 0 || circle.cy < 0 || circle.cx > lens_size.width ||
      circle.cy > lens_size.height) {
    return what + ": its centre is outside the " + SizeText(lens_size) +
           " lens image";
  }
  const double diagonal = std::hypot(lens_size.width, lens_size.height);
  if (circle.r > 2 * diagonal) {
    return what + ": its radius is more than twice the diagonal of the " +
           SizeText(lens_size) + " lens image";
  }
  const double covered = CoveredFraction(circle, lens_size);
  if (covered < kMinImageCircleCoverage) {
    char text[160];
    std::snprintf(text,
                  sizeof(text),
                  " covers %.1f%% of the %s lens image (at least %.0f%%: "
                  "is it the circle of another image size?)",
                  100 * covered,
                  SizeText(lens_size).c_str(),
                  100 * kMinImageCircleCoverage);
    return what + text;
  }
  return "";
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
  const double level =
      image.depth() == CV_16U ? black_level * 257.0 : black_level;
  cv::Mat bright;
  cv::compare(MaxColourChannel(image), level, bright, cv::CMP_GT);
  return bright;
}

double DarkRimFraction(const cv::Mat& lens_image,
                       const ImageCircle& circle,
                       int black_level,
                       int* num_directions) {
  const cv::Mat intensity = NormalizedIntensity(lens_image);
  const double black = black_level / 255.0;
  const double gap = std::max(1.0, 0.005 * circle.r);
  const double width = std::max(2.0, 0.02 * circle.r);
  const auto band_mean = [&](const std::vector<float>& profile,
                             double expected_size,
                             double* mean) {
    if (profile.size() + 0.5 < expected_size || profile.empty()) {
      return false;
    }
    double sum = 0;
    for (const float value : profile) {
      sum += value;
    }
    *mean = sum / profile.size();
    return true;
  };
  constexpr int kNumDirections = 360;
  constexpr int kNumOuterBands = 3;
  int num_counted = 0;
  int num_dark = 0;
  const cv::Point2d centre(circle.cx, circle.cy);
  for (int direction = 0; direction < kNumDirections; ++direction) {
    const double angle = 2 * CV_PI * direction / kNumDirections;
    const double inner_begin = std::max(0.0, circle.r - gap - width);
    const std::vector<float> inner =
        RayProfile(intensity, centre, angle, inner_begin, circle.r - gap);
    double inner_mean = 0;
    double outer_mean = 0;
    if (!band_mean(inner, 1, &inner_mean) || inner_mean <= black) {
      continue;
    }
    // The darkest of up to kNumOuterBands bands side by side outside the
    // circle, the first of which must be in the image; and that first band.
    bool outer_visible = false;
    double first_mean = 0;
    double last_mean = 0;
    for (int band = 0; band < kNumOuterBands; ++band) {
      const double begin = circle.r + gap + band * width;
      double mean = 0;
      if (!band_mean(RayProfile(intensity, centre, angle, begin, begin + width),
                     std::floor(width) + 1,
                     &mean)) {
        break;
      }
      if (!outer_visible) {
        first_mean = mean;
      }
      last_mean = mean;
      outer_mean = outer_visible ? std::min(outer_mean, mean) : mean;
      outer_visible = true;
    }
    if (!outer_visible) {
      continue;
    }
    ++num_counted;
    // Dark outside, or the bright inner edge of a lens housing right at the
    // circle (its rim catching light beside a darker picture), fading
    // outwards.
    if (outer_mean <= kMaxDarkRatio * inner_mean ||
        (kMaxDarkRatio * first_mean >= inner_mean && first_mean > last_mean)) {
      ++num_dark;
    }
  }
  if (num_directions != nullptr) {
    *num_directions = num_counted;
  }
  return num_counted > 0 ? static_cast<double>(num_dark) / num_counted : 0.0;
}

std::string LensImageCircleError(const cv::Mat& lens_image,
                                 const ImageCircle& circle,
                                 int black_level) {
  int num_directions = 0;
  const double fraction =
      DarkRimFraction(lens_image, circle, black_level, &num_directions);
  if (num_directions == 0) {
    return "no part of the rim of its image circle " + CircleText(circle) +
           " is in the image with the picture inside it brighter than the "
           "black level " +
           std::to_string(black_level) +
           ", so the frame cannot be told from a normal photo";
  }
  if (fraction < kMinDarkRimFraction) {
    char text[320];
    std::snprintf(text,
                  sizeof(text),
                  "only %.0f%% of the rim of its image circle ends the "
                  "picture (dark outside, or a housing's bright rim; at "
                  "least %.0f%% must): not a dual-fisheye frame (a normal "
                  "photo or an equirectangular panorama?)",
                  100 * fraction,
                  100 * kMinDarkRimFraction);
    return text;
  }
  return "";
}

std::string DualFisheyeFrameError(const std::array<cv::Mat, 2>& lens_images,
                                  const std::array<ImageCircle, 2>& circles,
                                  int black_level) {
  for (int lens = 0; lens < 2; ++lens) {
    if (const std::string error = LensImageError(lens_images[lens]);
        !error.empty()) {
      return "lens " + std::to_string(lens) + ": " + error;
    }
  }
  if (lens_images[0].size() != lens_images[1].size() ||
      lens_images[0].type() != lens_images[1].type()) {
    return "the lens images differ: " + SizeText(lens_images[0].size()) +
           " with " + std::to_string(lens_images[0].channels()) +
           " channel(s) and " + SizeText(lens_images[1].size()) + " with " +
           std::to_string(lens_images[1].channels()) +
           " channel(s) (or their bit depths)";
  }
  for (int lens = 0; lens < 2; ++lens) {
    if (const std::string error =
            LensImageCircleError(lens_images[lens], circles[lens], black_level);
        !error.empty()) {
      return "lens " + std::to_string(lens) + ": " + error;
    }
  }
  return "";
}

std::string DetectImageCircle(const cv::Mat& lens_image,
                              int black_level,
                              ImageCircle* circle) {
  if (const std::string error = LensImageError(lens_image); !error.empty()) {
    return error;
  }
  cv::Mat intensity = NormalizedIntensity(lens_image);
  const double sigma =
      std::max(1.0, std::min(lens_image.cols, lens_image.rows) / 1000.0);
  cv::GaussianBlur(intensity, intensity, cv::Size(), sigma);
  ImageCircle edge_circle;
  if (const std::string error = DetectCircleEdge(intensity, &edge_circle);
      !error.empty()) {
    return error;
  }
  ImageCircle disc;
  const double agreement = std::max(2.0, 0.01 * edge_circle.r);
  if (DetectBrightDisc(lens_image, black_level, &disc).empty() &&
      std::abs(disc.cx - edge_circle.cx) <= agreement &&
      std::abs(disc.cy - edge_circle.cy) <= agreement &&
      std::abs(disc.r - edge_circle.r) <= agreement) {
    *circle = disc;
  } else {
    *circle = edge_circle;
  }
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

LensImage CutImageCircle(const cv::Mat& lens_image, const ImageCircle& circle) {
  if (const std::string error = LensImageError(lens_image); !error.empty()) {
    throw std::invalid_argument(error);
  }
  if (const std::string error = ImageCircleError(circle, lens_image.size());
      !error.empty()) {
    throw std::invalid_argument(error);
  }
  LensImage lens;
  lens.mask = ImageCircleMask(lens_image.size(), circle);
  lens.image = lens_image.clone();
  lens.image.setTo(cv::Scalar::all(0), lens.mask == 0);
  return lens;
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
