// The sensor stage of the renderer: what a real camera does to the light the
// lens projection (render.h) delivers, before the writer stores the frame.
// The lens projection is ideal and stays so; everything here only changes
// pixels, never the geometry, so the ground truth is the same with or
// without effects.
//
// In the order light meets them (all off by default; off, the frame is
// exactly ToEightBit(radiance), the plain renderer's image):
//   1. vignetting: the lens passes less light towards the rim of its circle;
//   2. flare: a smooth bright blob and a streak of stray light on the scene;
//   3. image circle: outside it the sensor sees the lens housing (a grey-brown
//      ring with some texture) and beyond that a dim surround, not black; the
//      circle may be larger than the frame and be cropped by its edges;
//   4. exposure and white balance: a gain per lens and per channel, drawn per
//      lens (the lenses of a rig meter separately);
//   5. Gaussian read noise in DN, then rounding to 8 bits;
//   6. JPEG compression at a given quality (applied by the writer).
// The ground-truth observations (model_io.h, SamplePoints) are those of the
// ideal lens: those outside the effects' image circle fall on the housing;
// the written mask tells which pixels see the scene.
// Randomness (flare placement, housing texture, lens gains, noise) is drawn
// from `seed` and the lens or image index only: the same inputs give the
// same bytes, whatever the thread count.
#ifndef SPHERA_SYNTHETIC_SENSOR_EFFECTS_H_
#define SPHERA_SYNTHETIC_SENSOR_EFFECTS_H_

#include <cstdint>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "synthetic/render.h"

namespace sphera {
namespace synthetic {

// Field names are the sphera_render option names (--circle_radius, ...);
// levels are in 8-bit digital numbers (DN, 0..255).
struct SensorEffects {
  // Image circle radius as a multiple of half the frame height (0: none; 1.05
  // crops the circle at the top and bottom edges, as many 360° cameras do).
  // Centred on the camera's own image circle if it has one (a rig lens), else
  // on the frame centre, moved by circle_centre_offset_px. A lens that has its
  // own image circle (its field of view ends there) keeps the smaller radius.
  double circle_radius = 0;
  Eigen::Vector2d circle_centre_offset_px = Eigen::Vector2d::Zero();
  // Mean brightness of the lens housing ring just outside the image circle
  // (0: none), its width as a multiple of the circle radius, and the relative
  // amplitude of its mottled texture.
  double housing = 0;
  double housing_width = 0.06;
  double housing_texture = 0.25;
  // Brightness beyond the housing (outside the circle without a housing).
  double surround = 0;
  // Fraction of light lost at the rim of the image circle (at the frame's
  // half-diagonal without a circle): gain(rho) = (1 - v) + v (1 - rho^2)^2,
  // rho = radius / rim radius, i.e. cos^4 of the angle whose sine is rho.
  double vignetting = 0;
  // Peak DN of the flare blob added to the scene (0: none); the blob's
  // standard deviation as a multiple of the circle radius.
  double flare = 0;
  double flare_size = 0.25;
  // Standard deviation of every lens's exposure, in stops (gain 2^(s N(0,1))),
  // and of its red and blue gains relative to green, in stops.
  double exposure_jitter = 0;
  double white_balance_jitter = 0;
  // Standard deviation of additive Gaussian read noise in DN.
  double noise_sigma = 0;
  // JPEG quality of the written frames, 1..100 (0: the writer's default, 95).
  int jpeg_quality = 0;
  uint64_t seed = 0;

  // The preset of `sphera_render --realistic`, modelled on a consumer
  // dual-fisheye camera: circle 1.05 x the half-height, housing, surround,
  // vignetting, flare, exposure and white-balance jitter, noise 2, JPEG 90.
  static SensorEffects Realistic();

  // Empty if valid, else a message that starts with the offending field's name.
  std::string Check() const;
};

// A lens's radiometry: exposure gain and per-channel white-balance gains
// (R, G, B; green is 1).
struct LensResponse {
  double exposure_gain = 1;
  Eigen::Vector3d white_balance_rgb = Eigen::Vector3d::Ones();
};

// The response of lens `lens_index` (a rig's sensor index, else the image
// index) drawn from the jitters and the seed.
LensResponse DrawLensResponse(const SensorEffects& effects, int lens_index);

// The circle (cx, cy, r) in pixels inside which the camera sees the scene:
// the effects' circle, else the camera's own; r = 0 if the whole frame sees it.
Eigen::Vector3d LensCircle(const VirtualCamera& camera, const SensorEffects& effects);

// COLMAP-style mask: CV_8U, 255 where the pixel centre lies in LensCircle
// (and so in the frame), 0 elsewhere.
cv::Mat ValidPixelMask(const VirtualCamera& camera, const SensorEffects& effects);

// The frame the sensor records (CV_8UC3) from a radiance image (CV_64FC3,
// RenderedImage::radiance) of `camera`. `lens_index` selects the lens's
// response and housing texture; `image_index` the flare and the noise.
cv::Mat ApplySensorEffects(const cv::Mat& radiance, const VirtualCamera& camera,
                           const SensorEffects& effects, int lens_index, uint64_t image_index);

}  // namespace synthetic
}  // namespace sphera

#endif  // SPHERA_SYNTHETIC_SENSOR_EFFECTS_H_
