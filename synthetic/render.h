// Rendering the synthetic room through any SPHERA camera model: every pixel
// is lifted to rays with sphera::RayFromImage (the same function the
// reconstruction uses), so the images are exact for the model by construction.
#ifndef SPHERA_SYNTHETIC_RENDER_H_
#define SPHERA_SYNTHETIC_RENDER_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "synthetic/scene.h"

namespace sphera {
namespace synthetic {

struct StitchSpec;

// One image to render: a camera model with its parameters and a pose.
struct VirtualCamera {
  // Image file name, e.g. "cam000.jpg"; a rig's images are "SENSOR/NAME".
  std::string name;
  std::string model_name;  // e.g. "EQUIRECTANGULAR"
  int model_id = -1;
  int width = 0;
  int height = 0;
  std::vector<double> params;
  // COLMAP convention: x_cam = cam_from_world_rotation * x_world + cam_from_world_translation.
  Eigen::Quaterniond cam_from_world_rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d cam_from_world_translation = Eigen::Vector3d::Zero();
  // The lens's image circle (cx, cy, radius) in pixels: pixels whose centre
  // lies outside are black and have no depth (a fisheye lens whose image
  // circle ends inside the sensor). Radius 0: the whole image.
  Eigen::Vector3d image_circle = Eigen::Vector3d::Zero();
  // Rig sensor of the image (empty: not part of a rig).
  std::string sensor;
  // Set only for a stitched panorama: its pixels are blended from these
  // lenses as a stitcher does that assumes they share one centre.
  std::shared_ptr<const StitchSpec> stitch;

  Eigen::Vector3d CentreInWorld() const;
  // True if the centre of pixel (col, row) lies in the image circle.
  bool InImageCircle(int col, int row) const;
  // Empty string if valid, else a message naming the camera and the problem
  // (unknown model, wrong parameter count or values, bad size).
  std::string Check() const;
};

// How a stitched panorama is made from the lens images of one rig frame:
// the panorama's ray d (in world) is looked up in every lens that sees it
// from the lens's own centre, along d itself (distance_m = 0: the lenses
// are assumed to share a centre, i.e. stitched at infinity) or towards the
// point at distance_m from the panorama's centre (a stitcher's fixed
// stitching distance). Weights: the lens whose axis is closest to d has
// weight 1, every other lens k has clamp((theta_min + band - theta_k) /
// band, 0, 1), where theta is the angle between d and a lens's axis; the
// weights are normalised (a linear blend across the seam).
struct StitchSpec {
  std::vector<VirtualCamera> lenses;
  double band_deg = 10;
  double distance_m = 0;
};

// Builds a camera from a pose given as centre and world_from_cam rotation.
VirtualCamera MakeCamera(const std::string& name, const std::string& model_name, int width,
                         int height, const std::vector<double>& params,
                         const Eigen::Matrix3d& world_from_cam_rotation,
                         const Eigen::Vector3d& centre_in_world);

struct RenderOptions {
  // K x K stratified (N-rooks) sub-pixel rays per pixel, averaged (box filter).
  int supersample = 3;
  // 0: all hardware threads.
  int num_threads = 0;

  std::string Check() const;
};

// The lens projection stage: what reaches the sensor, before any sensor
// effect (synthetic/sensor_effects.h turns `radiance` into a recorded frame).
struct RenderedImage {
  // CV_64FC3, BGR (OpenCV order), the mean scene colour over the pixel's
  // sub-pixel rays in 8-bit units (255 = white surface); 0 outside the model's
  // domain and outside the camera's image circle.
  cv::Mat radiance;
  cv::Mat image;  // CV_8UC3, ToEightBit(radiance): the ideal, noise-free frame
  cv::Mat depth;  // CV_32F, range along the pixel-centre ray in metres, 0 if no hit
};

// Renders `camera` (which must pass Check()). Deterministic given the scene,
// the camera and the options.
RenderedImage Render(const Scene& scene, const VirtualCamera& camera,
                     const RenderOptions& options);

// CV_64FC3 in 8-bit units to CV_8UC3: every value rounded half away from zero
// and clamped to [0, 255].
cv::Mat ToEightBit(const cv::Mat& radiance);

// Writes a rendered range map (a CV_32F image) in the range-map file format
// of synthetic/file_formats.h (read with sphera::ReadRangeMap); false where
// the file cannot be written.
bool WriteDepthMap(const std::string& path, const cv::Mat& depth);

}  // namespace synthetic
}  // namespace sphera

#endif  // SPHERA_SYNTHETIC_RENDER_H_
