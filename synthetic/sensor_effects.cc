#include "synthetic/sensor_effects.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include <opencv2/imgproc.hpp>

namespace sphera {
namespace synthetic {
namespace {

// splitmix64: decorrelates the seeds of the different random streams.
uint64_t Mix(uint64_t value) {
  value += 0x9e3779b97f4a7c15ULL;
  value = (value ^ (value >> 30)) * 0xbf58476d1ce4e5b9ULL;
  value = (value ^ (value >> 27)) * 0x94d049bb133111ebULL;
  return value ^ (value >> 31);
}

uint64_t StreamSeed(uint64_t seed, uint64_t stream, uint64_t index) {
  return Mix(Mix(seed ^ stream) + index);
}

constexpr uint64_t kLensStream = 0x6c656e73ULL;     // "lens"
constexpr uint64_t kHousingStream = 0x686f7573ULL;  // "hous"
constexpr uint64_t kFlareStream = 0x666c6172ULL;    // "flar"

// Colours (R, G, B), mean 1: the grey-brown of a lens housing, the warm tint
// of flare from an incandescent or low sun.
const Eigen::Vector3d kHousingTint(1.1, 1.0, 0.9);
const Eigen::Vector3d kFlareTint(1.05, 1.0, 0.95);

// A smooth random field over the frame with mean 0 and standard deviation 1
// (blurred white noise on a grid 8x coarser, upsampled): the housing's
// mottled texture.
cv::Mat SmoothNoise(int width, int height, uint64_t seed) {
  cv::Mat coarse(height / 8 + 2, width / 8 + 2, CV_64F);
  cv::RNG rng(seed);
  rng.fill(coarse, cv::RNG::NORMAL, 0.0, 1.0);
  cv::GaussianBlur(coarse, coarse, cv::Size(0, 0), 1.0);
  cv::Scalar mean, stddev;
  cv::meanStdDev(coarse, mean, stddev);
  coarse = (coarse - mean[0]) / std::max(stddev[0], 1e-12);
  cv::Mat field;
  cv::resize(coarse, field, cv::Size(width, height), 0, 0, cv::INTER_CUBIC);
  return field;
}

// Brightness of the surround at distance `outside_px` beyond the image
// circle: the housing ring (brightest at its inner edge, where the front
// element's rim catches light), then the surround; `texture` is the
// SmoothNoise value at the pixel.
double SurroundLevel(const SensorEffects& effects, double outside_px, double ring_px,
                     double texture) {
  const double mottle = 1 + effects.housing_texture * texture;
  const double surround = effects.surround * (1 + 0.5 * effects.housing_texture * texture);
  if (effects.housing <= 0 || ring_px <= 0) return surround;
  const double u = outside_px / ring_px;
  const double ring = effects.housing * mottle * (1.5 - u);  // mean housing over the ring
  // A 2-pixel blend from the ring into the surround.
  const double blend = std::clamp((outside_px - ring_px) / 2 + 0.5, 0.0, 1.0);
  return (1 - blend) * ring + blend * surround;
}

}  // namespace

SensorEffects SensorEffects::Realistic() {
  SensorEffects effects;
  effects.circle_radius = 1.05;
  effects.housing = 55;
  effects.surround = 14;
  effects.vignetting = 0.35;
  effects.flare = 40;
  effects.exposure_jitter = 0.25;
  effects.white_balance_jitter = 0.05;
  effects.noise_sigma = 2;
  effects.jpeg_quality = 90;
  return effects;
}

std::string SensorEffects::Check() const {
  struct Range {
    const char* name;
    double value, low, high;
    bool low_open, high_open;
    const char* meaning;
  };
  const Range ranges[] = {
      {"circle_radius", circle_radius, 0, 100, false, false,
       "0 (none) or a multiple of the half-height up to 100"},
      {"housing", housing, 0, 255, false, false, "a brightness in [0, 255] DN"},
      {"housing_width", housing_width, 0, 1, false, false,
       "a fraction of the circle radius in [0, 1]"},
      {"housing_texture", housing_texture, 0, 1, false, false, "in [0, 1]"},
      {"surround", surround, 0, 255, false, false, "a brightness in [0, 255] DN"},
      {"vignetting", vignetting, 0, 1, false, true,
       "a fraction of light lost at the rim in [0, 1)"},
      {"flare", flare, 0, 255, false, false, "a peak brightness in [0, 255] DN"},
      {"flare_size", flare_size, 0, 10, true, false, "a multiple of the circle radius in (0, 10]"},
      {"exposure_jitter", exposure_jitter, 0, 3, false, false,
       "a standard deviation in [0, 3] stops"},
      {"white_balance_jitter", white_balance_jitter, 0, 1, false, false,
       "a standard deviation in [0, 1] stops"},
      {"noise_sigma", noise_sigma, 0, 100, false, false, "a standard deviation in [0, 100] DN"},
      {"jpeg_quality", static_cast<double>(jpeg_quality), 0, 100, false, false,
       "in [1, 100] (0: the default, 95)"},
  };
  for (const Range& range : ranges) {
    const bool ok = std::isfinite(range.value) &&
                    (range.low_open ? range.value > range.low : range.value >= range.low) &&
                    (range.high_open ? range.value < range.high : range.value <= range.high);
    if (!ok) {
      std::ostringstream error;
      error << range.name << " must be " << range.meaning << " (got " << range.value << ")";
      return error.str();
    }
  }
  if (!circle_centre_offset_px.allFinite()) return "circle_centre_offset_px must be finite";
  return "";
}

LensResponse DrawLensResponse(const SensorEffects& effects, int lens_index) {
  std::mt19937_64 rng(StreamSeed(effects.seed, kLensStream, static_cast<uint64_t>(lens_index)));
  std::normal_distribution<double> normal(0.0, 1.0);
  const double exposure = normal(rng), red = normal(rng), blue = normal(rng);
  LensResponse response;
  response.exposure_gain = std::exp2(effects.exposure_jitter * exposure);
  response.white_balance_rgb = Eigen::Vector3d(std::exp2(effects.white_balance_jitter * red), 1,
                                               std::exp2(effects.white_balance_jitter * blue));
  return response;
}

Eigen::Vector3d LensCircle(const VirtualCamera& camera, const SensorEffects& effects) {
  const Eigen::Vector3d& own = camera.image_circle;
  if (effects.circle_radius <= 0) return own;
  const Eigen::Vector2d centre =
      (own.z() > 0 ? Eigen::Vector2d(own.x(), own.y())
                   : Eigen::Vector2d(camera.width / 2.0, camera.height / 2.0)) +
      effects.circle_centre_offset_px;
  double radius = effects.circle_radius * camera.height / 2.0;
  if (own.z() > 0) radius = std::min(radius, own.z());
  return Eigen::Vector3d(centre.x(), centre.y(), radius);
}

cv::Mat ValidPixelMask(const VirtualCamera& camera, const SensorEffects& effects) {
  VirtualCamera lens = camera;
  lens.image_circle = LensCircle(camera, effects);
  cv::Mat mask(camera.height, camera.width, CV_8U);
  for (int row = 0; row < camera.height; ++row) {
    uint8_t* out = mask.ptr<uint8_t>(row);
    for (int col = 0; col < camera.width; ++col) {
      out[col] = lens.InImageCircle(col, row) && camera.InImageCircle(col, row) ? 255 : 0;
    }
  }
  return mask;
}

cv::Mat ApplySensorEffects(const cv::Mat& radiance, const VirtualCamera& camera,
                           const SensorEffects& effects, int lens_index, uint64_t image_index) {
  CV_Assert(radiance.type() == CV_64FC3 && radiance.rows == camera.height &&
            radiance.cols == camera.width);
  const int width = camera.width, height = camera.height;
  const Eigen::Vector3d circle = LensCircle(camera, effects);
  const bool has_circle = circle.z() > 0;
  // Radial effects are measured from the circle's centre and scaled by its
  // radius, or by the half-diagonal of a frame without a circle.
  const Eigen::Vector2d centre =
      has_circle ? Eigen::Vector2d(circle.x(), circle.y()) : Eigen::Vector2d(width / 2.0, height / 2.0);
  const double rim_px = has_circle ? circle.z() : 0.5 * std::hypot(width, height);
  const bool paints_surround = has_circle && (effects.circle_radius > 0 || effects.housing > 0 ||
                                              effects.surround > 0);
  const bool surround_is_lit = effects.housing > 0 || effects.surround > 0;
  const LensResponse response = DrawLensResponse(effects, lens_index);
  // BGR gains.
  const Eigen::Vector3d gain =
      response.exposure_gain * Eigen::Vector3d(response.white_balance_rgb.z(),
                                               response.white_balance_rgb.y(),
                                               response.white_balance_rgb.x());

  cv::Mat texture;
  if (paints_surround && surround_is_lit) {
    texture = SmoothNoise(width, height,
                          StreamSeed(effects.seed, kHousingStream, static_cast<uint64_t>(lens_index)));
  }

  // Flare: a Gaussian blob at a random place in the circle and a fainter
  // streak through it along the line to the centre, where lens ghosts line up.
  Eigen::Vector2d flare_centre = centre, streak_direction(1, 0);
  double flare_peak = 0, flare_sigma = 1;
  if (effects.flare > 0) {
    std::mt19937_64 rng(StreamSeed(effects.seed, kFlareStream, image_index));
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double angle = 2 * M_PI * unit(rng);
    const double distance = (0.4 + 0.5 * unit(rng)) * rim_px;
    streak_direction = Eigen::Vector2d(std::cos(angle), std::sin(angle));
    flare_centre = centre + distance * streak_direction;
    flare_peak = effects.flare * (0.6 + 0.4 * unit(rng));
    flare_sigma = effects.flare_size * rim_px;
  }

  const bool noisy = effects.noise_sigma > 0;
  const uint64_t noise_seed = effects.seed * 1000003ULL + image_index;
  cv::Mat light(height, width, CV_64FC3);
  for (int row = 0; row < height; ++row) {
    const cv::Vec3d* in = radiance.ptr<cv::Vec3d>(row);
    cv::Vec3d* out = light.ptr<cv::Vec3d>(row);
    const double* texture_row = texture.empty() ? nullptr : texture.ptr<double>(row);
    std::mt19937_64 rng(noise_seed * 0x9e3779b97f4a7c15ULL + static_cast<uint64_t>(row));
    std::normal_distribution<double> noise(0.0, 1.0);
    for (int col = 0; col < width; ++col) {
      const Eigen::Vector2d pixel(col + 0.5, row + 0.5);
      const double radius = (pixel - centre).norm();
      Eigen::Vector3d value(in[col][0], in[col][1], in[col][2]);
      if (effects.vignetting > 0) {
        const double rho2 = std::min(radius / rim_px, 1.0) * std::min(radius / rim_px, 1.0);
        value *= (1 - effects.vignetting) + effects.vignetting * (1 - rho2) * (1 - rho2);
      }
      if (flare_peak > 0) {
        const Eigen::Vector2d offset = pixel - flare_centre;
        const double along = offset.dot(streak_direction);
        const double across = offset.x() * streak_direction.y() - offset.y() * streak_direction.x();
        const double blob = std::exp(-offset.squaredNorm() / (2 * flare_sigma * flare_sigma));
        const double streak_sigma = 0.1 * flare_sigma, streak_length = 1.5 * rim_px;
        const double streak = 0.3 * std::exp(-across * across / (2 * streak_sigma * streak_sigma) -
                                             along * along / (2 * streak_length * streak_length));
        // BGR order of the tint.
        value += flare_peak * (blob + streak) *
                 Eigen::Vector3d(kFlareTint.z(), kFlareTint.y(), kFlareTint.x());
      }
      bool lit = true;
      if (paints_surround) {
        const double outside_px = radius - circle.z();
        // The circle's edge is soft over one pixel.
        const double scene_weight = std::clamp(0.5 - outside_px, 0.0, 1.0);
        if (scene_weight < 1) {
          const double level = surround_is_lit ? SurroundLevel(effects, std::max(outside_px, 0.0),
                                                               effects.housing_width * circle.z(),
                                                               texture_row[col])
                                               : 0.0;
          value = scene_weight * value + (1 - scene_weight) * level *
                                             Eigen::Vector3d(kHousingTint.z(), kHousingTint.y(),
                                                             kHousingTint.x());
        }
        lit = scene_weight > 0 || surround_is_lit;
      } else if (!camera.InImageCircle(col, row)) {
        lit = surround_is_lit;  // the plain renderer's black outside a lens's own circle
      }
      value = value.cwiseProduct(gain);
      // Read noise, drawn R, G, B per pixel as the plain renderer did; a
      // pixel that receives no light at all stays exactly black.
      if (noisy && lit) {
        for (int c = 0; c < 3; ++c) value[2 - c] += effects.noise_sigma * noise(rng);
      }
      out[col] = cv::Vec3d(value.x(), value.y(), value.z());
    }
  }
  return ToEightBit(light);
}

}  // namespace synthetic
}  // namespace sphera
