#include "synthetic/render.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include "camera_models/registry.h"
#include "synthetic/file_formats.h"

namespace sphera {
namespace synthetic {

Eigen::Vector3d VirtualCamera::CentreInWorld() const {
  return -(cam_from_world_rotation.conjugate() * cam_from_world_translation);
}

std::string VirtualCamera::Check() const {
  std::ostringstream error;
  error << "camera '" << name << "': ";
  // One optional folder level ("SENSOR/NAME", a rig's layout).
  const size_t slash = name.find('/');
  const bool bad_folder =
      slash != std::string::npos &&
      (slash == 0 || slash + 1 == name.size() || name.find('/', slash + 1) != std::string::npos ||
       name.compare(0, slash, ".") == 0 || name.compare(0, slash, "..") == 0);
  if (name.empty() || name.find_first_of(" \t\n\\") != std::string::npos || bad_folder) {
    error << "image name must be non-empty, contain no blanks and at most one folder "
             "(SENSOR/NAME)";
    return error.str();
  }
  const int id = ModelIdFromName(model_name);
  if (id < 0) {
    error << "unknown camera model '" << model_name << "'";
    return error.str();
  }
  if (model_id != id) {
    error << "model id " << model_id << " does not match model " << model_name;
    return error.str();
  }
  if (width <= 0 || height <= 0 || width > 65536 || height > 65536) {
    error << "bad image size " << width << " x " << height;
    return error.str();
  }
  for (size_t i = 0; i < params.size(); ++i) {
    if (!std::isfinite(params[i])) {
      error << "parameter " << i << " is not finite";
      return error.str();
    }
  }
  const std::string model_error = CheckParams(model_id, params, width, height);
  if (!model_error.empty()) {
    error << model_error;
    return error.str();
  }
  const Eigen::Vector4d q = cam_from_world_rotation.coeffs();
  if (!q.allFinite() || std::abs(q.norm() - 1) > 1e-6 ||
      !cam_from_world_translation.allFinite()) {
    error << "pose must have a unit quaternion and a finite translation";
    return error.str();
  }
  if (!image_circle.allFinite() || image_circle.z() < 0) {
    error << "image circle must be finite with radius >= 0";
    return error.str();
  }
  if (stitch) {
    if (stitch->lenses.empty() || !(stitch->band_deg > 0) || !(stitch->distance_m >= 0)) {
      error << "stitched panorama needs lenses, a blend band > 0 and a distance >= 0";
      return error.str();
    }
    for (const VirtualCamera& lens : stitch->lenses) {
      if (lens.stitch) {
        error << "a stitched panorama's lens cannot itself be stitched";
        return error.str();
      }
      const std::string lens_error = lens.Check();
      if (!lens_error.empty()) {
        error << "lens " << lens_error;
        return error.str();
      }
    }
  }
  return "";
}

bool VirtualCamera::InImageCircle(int col, int row) const {
  if (image_circle.z() <= 0) return true;
  const double dx = col + 0.5 - image_circle.x(), dy = row + 0.5 - image_circle.y();
  return dx * dx + dy * dy <= image_circle.z() * image_circle.z();
}

VirtualCamera MakeCamera(const std::string& name, const std::string& model_name, int width,
                         int height, const std::vector<double>& params,
                         const Eigen::Matrix3d& world_from_cam_rotation,
                         const Eigen::Vector3d& centre_in_world) {
  VirtualCamera camera;
  camera.name = name;
  camera.model_name = model_name;
  camera.model_id = ModelIdFromName(model_name);
  camera.width = width;
  camera.height = height;
  camera.params = params;
  camera.cam_from_world_rotation = Eigen::Quaterniond(world_from_cam_rotation.transpose());
  camera.cam_from_world_rotation.normalize();
  camera.cam_from_world_translation = -(camera.cam_from_world_rotation * centre_in_world);
  return camera;
}

std::string RenderOptions::Check() const {
  std::ostringstream error;
  if (supersample < 1 || supersample > 16) {
    error << "supersample must be in [1, 16] (got " << supersample << ")";
  } else if (num_threads < 0) {
    error << "num_threads must be >= 0 (got " << num_threads << ")";
  }
  return error.str();
}

RenderedImage Render(const Scene& scene, const VirtualCamera& camera,
                     const RenderOptions& options) {
  const int width = camera.width, height = camera.height;
  RenderedImage out;
  out.radiance.create(height, width, CV_64FC3);
  out.depth.create(height, width, CV_32F);

  const Eigen::Matrix3d world_from_cam = camera.cam_from_world_rotation.conjugate().toRotationMatrix();
  const Eigen::Vector3d centre = camera.CentreInWorld();
  const int k = options.supersample;
  const double inv_samples = 1.0 / (k * k);

  // A lens of a stitched panorama as the stitcher sees it.
  struct StitchLens {
    Eigen::Matrix3d cam_from_world;
    Eigen::Vector3d centre;
    Eigen::Vector3d axis;  // optical axis in world
    const VirtualCamera* camera;
  };
  std::vector<StitchLens> stitch_lenses;
  if (camera.stitch) {
    for (const VirtualCamera& lens : camera.stitch->lenses) {
      const Eigen::Matrix3d cam_from_world = lens.cam_from_world_rotation.toRotationMatrix();
      stitch_lenses.push_back(
          {cam_from_world, lens.CentreInWorld(), cam_from_world.row(2).transpose(), &lens});
    }
  }

  // Colour of the scene along `ray_in_world` from `origin`; range of the hit
  // in `range` (0 if nothing is hit).
  auto cast = [&](const Eigen::Vector3d& origin, const Eigen::Vector3d& ray_in_world,
                  Eigen::Vector3f* colour, double* range) {
    RayHit hit;
    if (scene.CastRay(origin, ray_in_world, &hit)) {
      *colour = scene.Colour(hit.face_id, hit.point);
      *range = hit.range;
    } else {
      colour->setZero();
      *range = 0;
    }
  };

  // A stitched panorama's colour in direction `d` (world): the blend of the
  // lenses that see it (see StitchSpec). False if no lens sees it.
  auto stitched = [&](const Eigen::Vector3d& d, Eigen::Vector3f* colour, double* range) {
    const StitchSpec& spec = *camera.stitch;
    std::vector<double> theta(stitch_lenses.size(), 1e9);
    std::vector<Eigen::Vector3d> dirs(stitch_lenses.size());
    double theta_min = 1e9;
    for (size_t k = 0; k < stitch_lenses.size(); ++k) {
      const StitchLens& lens = stitch_lenses[k];
      dirs[k] = spec.distance_m > 0 ? (centre + spec.distance_m * d - lens.centre).normalized() : d;
      Eigen::Vector2d pixel;
      if (!ImageFromRay(lens.camera->model_id, lens.camera->params, lens.cam_from_world * dirs[k],
                        &pixel) ||
          !(pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() < lens.camera->width &&
            pixel.y() < lens.camera->height) ||
          !lens.camera->InImageCircle(static_cast<int>(pixel.x()), static_cast<int>(pixel.y()))) {
        continue;
      }
      theta[k] = std::acos(std::clamp(lens.axis.dot(d), -1.0, 1.0));
      theta_min = std::min(theta_min, theta[k]);
    }
    if (theta_min > 1e8) return false;
    const double band = spec.band_deg * M_PI / 180;
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    double weight_sum = 0, best_weight = 0;
    for (size_t k = 0; k < stitch_lenses.size(); ++k) {
      const double weight = std::clamp((theta_min + band - theta[k]) / band, 0.0, 1.0);
      if (weight <= 0) continue;
      Eigen::Vector3f lens_colour;
      double lens_range = 0;
      cast(stitch_lenses[k].centre, dirs[k], &lens_colour, &lens_range);
      sum += static_cast<float>(weight) * lens_colour;
      weight_sum += weight;
      if (weight > best_weight) best_weight = weight, *range = lens_range;
    }
    *colour = sum / static_cast<float>(weight_sum);
    return true;
  };

  // Colour of the scene along the ray through `pixel`; false outside the
  // model's domain. Range of the hit in `range` (0 if nothing is hit).
  auto trace = [&](const Eigen::Vector2d& pixel, Eigen::Vector3f* colour, double* range) {
    Eigen::Vector3d ray_in_cam;
    if (!RayFromImage(camera.model_id, camera.params, pixel, &ray_in_cam)) return false;
    const Eigen::Vector3d ray_in_world = (world_from_cam * ray_in_cam).normalized();
    if (camera.stitch) return stitched(ray_in_world, colour, range);
    cast(centre, ray_in_world, colour, range);
    return true;
  };

  auto render_row = [&](int row) {
    cv::Vec3d* radiance_row = out.radiance.ptr<cv::Vec3d>(row);
    float* depth_row = out.depth.ptr<float>(row);
    for (int col = 0; col < width; ++col) {
      if (!camera.InImageCircle(col, row)) {
        depth_row[col] = 0;
        radiance_row[col] = cv::Vec3d(0, 0, 0);
        continue;
      }
      // Pixel (col, row) covers [col, col+1] x [row, row+1]; its centre is
      // (col + 0.5, row + 0.5) (COLMAP convention). Sub-pixel samples are
      // stratified (one per cell of a K x K grid) and N-rooks (all K^2 x and
      // all K^2 y offsets distinct): a near-axis-aligned edge is resolved to
      // 1/K^2 px instead of 1/K px. Their mean is exactly the pixel centre,
      // and for odd K the middle sample is the centre itself.
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      double centre_range = 0;
      bool centre_done = false;
      for (int sy = 0; sy < k; ++sy) {
        for (int sx = 0; sx < k; ++sx) {
          const Eigen::Vector2d pixel(col + (sx + (sy + 0.5) / k) / k,
                                      row + (sy + (sx + 0.5) / k) / k);
          // With odd K the middle sample is the pixel centre: reuse it for depth.
          const bool is_centre = (k % 2 == 1) && sx == k / 2 && sy == k / 2;
          Eigen::Vector3f colour;
          double range = 0;
          if (trace(pixel, &colour, &range)) {
            sum += colour;
            if (is_centre) centre_range = range;
          }
          centre_done = centre_done || is_centre;
        }
      }
      if (!centre_done) {
        Eigen::Vector3f colour;
        if (!trace(Eigen::Vector2d(col + 0.5, row + 0.5), &colour, &centre_range)) centre_range = 0;
      }
      depth_row[col] = static_cast<float>(centre_range);
      // OpenCV stores BGR.
      for (int c = 0; c < 3; ++c) radiance_row[col][2 - c] = 255.0 * sum[c] * inv_samples;
    }
  };

  int num_threads = options.num_threads > 0
                        ? options.num_threads
                        : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  num_threads = std::min(num_threads, height);
  std::atomic<int> next_row(0);
  auto worker = [&]() {
    for (int row = next_row++; row < height; row = next_row++) render_row(row);
  };
  std::vector<std::thread> threads;
  for (int t = 1; t < num_threads; ++t) threads.emplace_back(worker);
  worker();
  for (std::thread& thread : threads) thread.join();
  out.image = ToEightBit(out.radiance);
  return out;
}

cv::Mat ToEightBit(const cv::Mat& radiance) {
  cv::Mat image(radiance.rows, radiance.cols, CV_8UC3);
  for (int row = 0; row < radiance.rows; ++row) {
    const double* in = radiance.ptr<double>(row);
    uint8_t* out = image.ptr<uint8_t>(row);
    // std::lround rather than cv::saturate_cast, which rounds halves to even.
    for (int i = 0; i < 3 * radiance.cols; ++i) {
      out[i] = static_cast<uint8_t>(std::clamp(std::lround(in[i]), 0L, 255L));
    }
  }
  return image;
}

bool WriteDepthMap(const std::string& path, const cv::Mat& depth) {
  if (depth.type() != CV_32F) return false;
  RangeMap map;
  map.width = depth.cols;
  map.height = depth.rows;
  map.ranges.reserve(static_cast<size_t>(depth.total()));
  for (int row = 0; row < depth.rows; ++row) {
    map.ranges.insert(map.ranges.end(), depth.ptr<float>(row), depth.ptr<float>(row) + depth.cols);
  }
  return WriteRangeMap(path, map);
}

}  // namespace synthetic
}  // namespace sphera
