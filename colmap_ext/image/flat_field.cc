#include "colmap_ext/image/flat_field.h"

#include "colmap/math/math.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

namespace colmap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A bin needs this many valid pixels.
constexpr int kMinBinPixels = 50;
// The outermost bins (the rim's blur and the housing's edge) are not fitted.
constexpr double kMaxFitRho = 0.97;

double BinRho(int bin) {
  return (bin + 0.5) / RadialFalloffEstimator::kNumBins;
}

}  // namespace

double RadialFalloff::Gain(double rho) const {
  // Past the polynomial's lowest point (where a fit flattening at the rim
  // turns up again) the gain stays there.
  double rho2 = rho * rho;
  if (a < 0 && b > 0) rho2 = std::min(rho2, -a / (2 * b));
  return 1 + a * rho2 + b * rho2 * rho2;
}

RadialFalloffEstimator::RadialFalloffEstimator(const ImageCircle& circle,
                                               int black_level)
    : circle_(circle), black_level_(black_level) {}

void RadialFalloffEstimator::Add(const cv::Mat& image) {
  cv::Mat grey = image;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  }
  if (grey.type() != CV_8UC1 || circle_.r <= 0) return;
  std::vector<double> sums(kNumBins, 0);
  std::vector<int> counts(kNumBins, 0);
  const int y0 = std::max(0, static_cast<int>(circle_.cy - circle_.r));
  const int y1 = std::min(grey.rows, static_cast<int>(circle_.cy + circle_.r) + 1);
  const int x0 = std::max(0, static_cast<int>(circle_.cx - circle_.r));
  const int x1 = std::min(grey.cols, static_cast<int>(circle_.cx + circle_.r) + 1);
  for (int y = y0; y < y1; ++y) {
    const uint8_t* row = grey.ptr<uint8_t>(y);
    for (int x = x0; x < x1; ++x) {
      // Pixel centres at +0.5, the circle in the same convention.
      const double rho =
          std::hypot(x + 0.5 - circle_.cx, y + 0.5 - circle_.cy) / circle_.r;
      const int bin = static_cast<int>(rho * kNumBins);
      if (bin >= kNumBins) continue;
      const int value = row[x];
      if (value <= black_level_ || value >= 255) continue;
      sums[bin] += value;
      ++counts[bin];
    }
  }
  // Relative to the image's mean over the circle: each image's own
  // brightness (exposure, scene) out; the level is fitted with the shape.
  double total_sum = 0;
  int total_count = 0;
  for (int bin = 0; bin < kNumBins && BinRho(bin) <= kMaxFitRho; ++bin) {
    total_sum += sums[bin];
    total_count += counts[bin];
  }
  if (total_count < kMinBinPixels * 8 || total_sum <= 0) return;
  const double mean = total_sum / total_count;
  std::vector<double> profile(kNumBins, kNaN);
  for (int bin = 0; bin < kNumBins; ++bin) {
    if (counts[bin] >= kMinBinPixels) {
      profile[bin] = sums[bin] / counts[bin] / mean;
    }
  }
  profiles_.push_back(std::move(profile));
}

RadialFalloff RadialFalloffEstimator::Fit(int min_images,
                                          double min_falloff,
                                          std::string* why) const {
  const auto identity = [&](const std::string& reason) {
    if (why != nullptr) *why = reason;
    return RadialFalloff();
  };
  if (NumImages() < min_images) {
    return identity(std::to_string(NumImages()) + " image(s) with enough pixels, " +
                    std::to_string(min_images) + " needed");
  }
  // Least squares of the median profile by c (1 + a rho^2 + b rho^4)
  // (linear in c, c a, c b), each bin weighted by its ring's area.
  std::vector<Eigen::Vector3d> rows;
  std::vector<double> targets;
  for (int bin = 0; bin < kNumBins; ++bin) {
    const double rho = BinRho(bin);
    if (rho > kMaxFitRho) break;
    std::vector<double> values;
    for (const std::vector<double>& profile : profiles_) {
      if (!std::isnan(profile[bin])) values.push_back(profile[bin]);
    }
    if (values.empty()) continue;
    const double median = Median(values);
    const double weight = std::sqrt(rho);
    rows.push_back(weight *
                   Eigen::Vector3d(1, rho * rho, std::pow(rho, 4)));
    targets.push_back(weight * median);
  }
  if (rows.size() < 8) {
    return identity("the images' circle has too few radii with pixels");
  }
  Eigen::MatrixXd design(rows.size(), 3);
  Eigen::VectorXd target(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    design.row(i) = rows[i].transpose();
    target(i) = targets[i];
  }
  const Eigen::Vector3d fit = design.colPivHouseholderQr().solve(target);
  if (!(fit(0) > 0)) {
    return identity("the images' profile has no level");
  }
  RadialFalloff falloff;
  falloff.a = fit(1) / fit(0);
  falloff.b = fit(2) / fit(0);
  // Darker outwards (within 1%, the fit's noise where it is flat), never
  // below 20%.
  double lowest = 1;
  for (int i = 1; i <= 100; ++i) {
    const double gain = falloff.Gain(i / 100.0);
    if (gain > lowest + 0.01 || gain <= 0.2) {
      return identity("the fitted fall-off is not a lens's (gain " +
                      std::to_string(gain) + " at " +
                      std::to_string(i / 100.0) + " of the radius)");
    }
    lowest = std::min(lowest, gain);
  }
  if (falloff.Gain(1) > 1 - min_falloff) {
    return identity("the rim is darker by less than " +
                    std::to_string(min_falloff));
  }
  if (why != nullptr) why->clear();
  return falloff;
}

void DivideByFalloff(const ImageCircle& circle,
                     const RadialFalloff& falloff,
                     cv::Mat* image) {
  if (falloff.IsIdentity() || circle.r <= 0) return;
  CV_Assert(image->depth() == CV_8U);
  const int channels = image->channels();
  for (int y = 0; y < image->rows; ++y) {
    uint8_t* row = image->ptr<uint8_t>(y);
    for (int x = 0; x < image->cols; ++x) {
      const double rho =
          std::hypot(x + 0.5 - circle.cx, y + 0.5 - circle.cy) / circle.r;
      if (rho >= 1) continue;
      const double scale = 1 / falloff.Gain(rho);
      for (int c = 0; c < channels; ++c) {
        row[x * channels + c] =
            cv::saturate_cast<uint8_t>(row[x * channels + c] * scale);
      }
    }
  }
}

}  // namespace colmap
