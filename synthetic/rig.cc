#include "synthetic/rig.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <random>
#include <sstream>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "camera_models/registry.h"

namespace sphera {
namespace synthetic {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = M_PI / 180;

Eigen::Matrix3d Yaw(double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

// world_from_body for a heading `yaw` about the vertical (+Y is down), then
// pitch about x and roll about z (as the layouts of model_io.cc).
Eigen::Matrix3d WorldFromBody(double yaw, double pitch, double roll) {
  return Yaw(yaw) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()).toRotationMatrix() *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// Radius of the projection of a ray at `angle` from the axis, in units of the
// focal length (fx = fy = 1, principal point 0), along azimuth 0.
bool UnitRadius(const std::string& model_name, std::vector<double> params, double angle,
                double* radius) {
  params[0] = params[1] = 1;
  params[2] = params[3] = 0;
  Eigen::Vector2d pixel;
  if (!ImageFromRay(ModelIdFromName(model_name), params,
                    Eigen::Vector3d(std::sin(angle), 0, std::cos(angle)), &pixel)) {
    return false;
  }
  *radius = pixel.norm();
  return *radius > 0;
}

// A lens of `size` x `size` pixels whose image circle (rays at `max_angle_deg`)
// has radius `circle_fraction` * size, with the distortion of `base` params.
std::string FitFocal(RigSensor* sensor, double circle_fraction, double focal_scale,
                     const Eigen::Vector2d& centre_offset) {
  double radius = 0;
  if (!UnitRadius(sensor->model_name, sensor->params, sensor->max_angle_deg * kDeg, &radius)) {
    return "lens '" + sensor->name + "': model " + sensor->model_name +
           " cannot project rays at " + std::to_string(sensor->max_angle_deg) + " degrees";
  }
  const double focal = circle_fraction * sensor->width / radius;
  sensor->params[0] = focal * focal_scale;
  sensor->params[1] = focal * focal_scale;
  sensor->params[2] = sensor->width / 2.0 + centre_offset.x();
  sensor->params[3] = sensor->height / 2.0 + centre_offset.y();
  return "";
}

std::string FrameName(int frame, const std::string& extension) {
  std::ostringstream name;
  name << "frame" << std::setw(3) << std::setfill('0') << frame << extension;
  return name.str();
}

std::string WriteText(const fs::path& path, const std::string& text) {
  std::ofstream file(path);
  file << text;
  file.close();
  return file ? "" : "cannot write " + path.string();
}

}  // namespace

std::string MakeRigPreset(const std::string& preset, int lens_size,
                          std::vector<RigSensor>* sensors) {
  sensors->clear();
  // Lens poses in the camera body (x right, y down, z forward), then taken
  // relative to lens 0, which is the rig's reference.
  std::vector<Eigen::Matrix3d> body_from_lens;
  std::vector<Eigen::Vector3d> centre_in_body;
  if (preset == "dual_fisheye") {
    const int size = lens_size > 0 ? lens_size : 1024;
    RigSensor front;
    front.name = "lens0";
    front.model_name = "DOUBLE_SPHERE";
    front.width = front.height = size;
    front.params = {1, 1, 0, 0, -0.2, 0.6};
    front.max_angle_deg = 100;
    RigSensor back = front;
    back.name = "lens1";
    back.model_name = "UNIFIED_OMNI";
    back.params = {1, 1, 0, 0, 1.1, 0.02, 0, 0, 0};
    std::string error = FitFocal(&front, 0.47, 1.0, Eigen::Vector2d(0, 0));
    if (error.empty()) error = FitFocal(&back, 0.47, 0.995, Eigen::Vector2d(1.5, -1.0));
    if (!error.empty()) return error;
    sensors->push_back(front);
    sensors->push_back(back);
    body_from_lens = {Eigen::Matrix3d::Identity(), Yaw(M_PI)};
    centre_in_body = {Eigen::Vector3d(0, 0, 0.015), Eigen::Vector3d(0, 0, -0.015)};
  } else if (preset == "ring8") {
    const int size = lens_size > 0 ? lens_size : 640;
    for (int k = 0; k < 8; ++k) {
      RigSensor lens;
      lens.name = "lens" + std::to_string(k);
      lens.model_name = "EUCM";
      lens.width = lens.height = size;
      lens.params = {1, 1, 0, 0, 0.6 + 0.01 * (k % 3), 1.0};
      lens.max_angle_deg = 97.5;
      const std::string error = FitFocal(&lens, 0.46, 1.0 + 0.002 * (k - 4),
                                         Eigen::Vector2d(0.5 * (k % 3) - 0.5, 0.3 * (k % 2)));
      if (!error.empty()) return error;
      sensors->push_back(lens);
      const double yaw = k * M_PI / 4;
      body_from_lens.push_back(Yaw(yaw));
      centre_in_body.emplace_back(0.06 * std::sin(yaw), k % 2 == 1 ? -0.01 : 0.0,
                                  0.06 * std::cos(yaw));
    }
  } else {
    return "unknown rig preset '" + preset + "' (expected dual_fisheye or ring8)";
  }
  // sensor_from_rig = lens_from_body * body_from_lens0 (rig = lens 0).
  for (size_t k = 0; k < sensors->size(); ++k) {
    const Eigen::Matrix3d lens_from_body = body_from_lens[k].transpose();
    const Eigen::Matrix3d rotation = lens_from_body * body_from_lens[0];
    // x_lens = lens_from_body * (x_body - c_k), x_body = body_from_lens0 * x_rig + c_0.
    const Eigen::Vector3d translation = lens_from_body * (centre_in_body[0] - centre_in_body[k]);
    Eigen::Quaterniond q = Eigen::Quaterniond(rotation).normalized();
    if (q.w() < 0) q.coeffs() = -q.coeffs();  // one sign for the files
    (*sensors)[k].sensor_from_rig_rotation = q;
    (*sensors)[k].sensor_from_rig_translation = translation;
  }
  (*sensors)[0].sensor_from_rig_rotation = Eigen::Quaterniond::Identity();
  (*sensors)[0].sensor_from_rig_translation.setZero();
  return "";
}

std::string ReadRigSensors(const std::string& path, std::vector<RigSensor>* sensors) {
  sensors->clear();
  const std::string error = ForEachDataLine(path, [&](const std::string& line,
                                                      const std::string& where) -> std::string {
    const size_t bar = line.find('|');
    if (bar == std::string::npos) {
      return where + "expected 'NAME MODEL WIDTH HEIGHT PARAMS... | QW QX QY QZ TX TY TZ "
                     "[MAX_ANGLE_DEG]'";
    }
    std::istringstream head(line.substr(0, bar));
    RigSensor sensor;
    std::string rest;
    if (!(head >> sensor.name >> sensor.model_name >> sensor.width >> sensor.height)) {
      return where + "expected NAME MODEL WIDTH HEIGHT before '|'";
    }
    std::getline(head, rest);
    std::vector<double> pose;
    if (!ParseParamList(rest, &sensor.params)) return where + "malformed parameter list";
    if (!ParseParamList(line.substr(bar + 1), &pose) || (pose.size() != 7 && pose.size() != 8)) {
      return where + "expected 7 or 8 numbers after '|': QW QX QY QZ TX TY TZ [MAX_ANGLE_DEG]";
    }
    const Eigen::Quaterniond q(pose[0], pose[1], pose[2], pose[3]);
    if (!(q.norm() > 1e-12)) return where + "zero quaternion";
    sensor.sensor_from_rig_rotation = q.normalized();
    sensor.sensor_from_rig_translation = Eigen::Vector3d(pose[4], pose[5], pose[6]);
    sensor.max_angle_deg = pose.size() == 8 ? pose[7] : 0;
    if (!(sensor.max_angle_deg >= 0 && sensor.max_angle_deg < 180)) {
      return where + "MAX_ANGLE_DEG must be in [0, 180)";
    }
    if (sensors->empty() &&
        (sensor.sensor_from_rig_rotation.angularDistance(Eigen::Quaterniond::Identity()) > 1e-12 ||
         sensor.sensor_from_rig_translation.norm() > 1e-12)) {
      return where + "the first lens is the rig's reference: its pose must be identity";
    }
    for (const RigSensor& other : *sensors) {
      if (other.name == sensor.name) return where + "duplicate lens name '" + sensor.name + "'";
    }
    sensors->push_back(sensor);
    return "";
  });
  if (!error.empty()) return error;
  if (sensors->empty()) return "rig sensor file " + path + " has no lenses";
  return "";
}

std::string ImageCircle(const RigSensor& sensor, Eigen::Vector3d* circle) {
  if (sensor.max_angle_deg <= 0) {
    circle->setZero();
    return "";
  }
  const int model_id = ModelIdFromName(sensor.model_name);
  if (model_id < 0 || sensor.params.size() < 4) {
    return "lens '" + sensor.name + "': an image circle needs a model with fx, fy, cx, cy";
  }
  const double angle = sensor.max_angle_deg * kDeg;
  const Eigen::Vector2d centre(sensor.params[2], sensor.params[3]);
  double sum = 0;
  for (int i = 0; i < 8; ++i) {
    const double azimuth = i * M_PI / 4;
    const Eigen::Vector3d ray(std::sin(angle) * std::cos(azimuth),
                              std::sin(angle) * std::sin(azimuth), std::cos(angle));
    Eigen::Vector2d pixel;
    if (!ImageFromRay(model_id, sensor.params, ray, &pixel)) {
      return "lens '" + sensor.name + "': rays at " + std::to_string(sensor.max_angle_deg) +
             " degrees do not project";
    }
    sum += (pixel - centre).norm();
  }
  *circle = Eigen::Vector3d(centre.x(), centre.y(), sum / 8);
  if (centre.x() - circle->z() < 0 || centre.y() - circle->z() < 0 ||
      centre.x() + circle->z() > sensor.width || centre.y() + circle->z() > sensor.height) {
    std::ostringstream error;
    error << "lens '" << sensor.name << "': image circle (" << centre.x() << ", " << centre.y()
          << ", r = " << circle->z() << ") is not inside its " << sensor.width << " x "
          << sensor.height << " image";
    return error.str();
  }
  return "";
}

std::vector<RigFrame> MakeFramePath(int num_frames, uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x72696770617468ULL);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<RigFrame> frames;
  for (int i = 0; i < num_frames; ++i) {
    const double phi = 2 * M_PI * i / num_frames;
    const Eigen::Vector3d centre(1.0 * std::sin(phi), 0.05 * unit(rng), 0.8 * std::cos(phi));
    const Eigen::Matrix3d world_from_rig =
        WorldFromBody(phi + M_PI / 2 + 10 * kDeg * unit(rng), 5 * kDeg * unit(rng),
                      5 * kDeg * unit(rng));
    RigFrame frame;
    frame.rig_from_world_rotation = Eigen::Quaterniond(world_from_rig.transpose()).normalized();
    frame.rig_from_world_translation = -(frame.rig_from_world_rotation * centre);
    frames.push_back(frame);
  }
  return frames;
}

std::string WriteRigDataset(const std::string& output_dir, const Scene& scene,
                            const std::vector<RigSensor>& sensors,
                            const std::vector<RigFrame>& frames,
                            const RigDatasetOptions& options, std::ostream* log) {
  if (sensors.empty()) return "a rig needs at least one lens";
  if (frames.empty()) return "a rig dataset needs at least one frame";
  std::vector<Eigen::Vector3d> circles(sensors.size());
  for (size_t k = 0; k < sensors.size(); ++k) {
    const std::string error = ImageCircle(sensors[k], &circles[k]);
    if (!error.empty()) return error;
  }
  if (options.raw && (sensors.size() != 2 || sensors[0].height != sensors[1].height)) {
    return "raw side-by-side frames need a rig of two lenses of the same height";
  }
  if (options.stitched && !(options.stitched_width >= 16 && options.stitched_width % 2 == 0)) {
    return "the stitched panorama width must be even and at least 16";
  }

  RigGroundTruth rig;
  for (const RigSensor& sensor : sensors) {
    rig.sensor_names.push_back(sensor.name);
    rig.sensor_from_rig_rotation.push_back(sensor.sensor_from_rig_rotation);
    rig.sensor_from_rig_translation.push_back(sensor.sensor_from_rig_translation);
  }
  std::vector<VirtualCamera> cameras;
  std::vector<std::vector<VirtualCamera>> frame_lenses(frames.size());
  for (size_t f = 0; f < frames.size(); ++f) {
    rig.rig_from_world_rotation.push_back(frames[f].rig_from_world_rotation);
    rig.rig_from_world_translation.push_back(frames[f].rig_from_world_translation);
    for (size_t k = 0; k < sensors.size(); ++k) {
      const RigSensor& sensor = sensors[k];
      VirtualCamera camera;
      camera.name = sensor.name + "/" + FrameName(static_cast<int>(f), options.image_extension);
      camera.model_name = sensor.model_name;
      camera.model_id = ModelIdFromName(sensor.model_name);
      camera.width = sensor.width;
      camera.height = sensor.height;
      camera.params = sensor.params;
      camera.sensor = sensor.name;
      camera.image_circle = circles[k];
      camera.cam_from_world_rotation =
          (sensor.sensor_from_rig_rotation * frames[f].rig_from_world_rotation).normalized();
      camera.cam_from_world_translation =
          sensor.sensor_from_rig_rotation * frames[f].rig_from_world_translation +
          sensor.sensor_from_rig_translation;
      cameras.push_back(camera);
      frame_lenses[f].push_back(camera);
      rig.image_sensor.push_back(static_cast<int>(k));
      rig.image_frame.push_back(static_cast<int>(f));
    }
  }

  DatasetOptions dataset = options.dataset;
  dataset.rig = &rig;
  dataset.extra = [&](const std::string& staging, std::ostream* extra_log) -> std::string {
    const fs::path tmp(staging);
    // The true rig for rig_configurator, and the image circles.
    std::ostringstream json, circles_txt;
    json << std::setprecision(17) << "[\n  {\n    \"cameras\": [\n";
    circles_txt << std::setprecision(17) << "# SENSOR CX CY R (pixels, image corner at 0, 0)\n";
    for (size_t k = 0; k < sensors.size(); ++k) {
      const RigSensor& sensor = sensors[k];
      json << "      {\n        \"image_prefix\": \"" << sensor.name << "/\",\n";
      if (k == 0) {
        json << "        \"ref_sensor\": true,\n";
      } else {
        const Eigen::Quaterniond& q = sensor.sensor_from_rig_rotation;
        const Eigen::Vector3d& t = sensor.sensor_from_rig_translation;
        json << "        \"cam_from_rig_rotation\": " << JsonList({q.w(), q.x(), q.y(), q.z()})
             << ",\n        \"cam_from_rig_translation\": " << JsonList({t.x(), t.y(), t.z()})
             << ",\n";
      }
      json << "        \"camera_model_name\": \"" << sensor.model_name << "\",\n"
           << "        \"camera_params\": " << JsonList(sensor.params) << "\n      }"
           << (k + 1 < sensors.size() ? "," : "") << "\n";
      circles_txt << sensor.name << " " << circles[k].x() << " " << circles[k].y() << " "
                  << circles[k].z() << "\n";
    }
    json << "    ]\n  }\n]\n";
    std::string error = WriteText(tmp / "rig_config.json", json.str());
    if (error.empty()) error = WriteText(tmp / "circles.txt", circles_txt.str());
    if (!error.empty()) return error;

    if (options.raw) {
      std::error_code ec;
      fs::create_directories(tmp / "raw", ec);
      if (ec) return "cannot create " + (tmp / "raw").string();
      for (size_t f = 0; f < frames.size(); ++f) {
        std::vector<cv::Mat> halves;
        for (const VirtualCamera& lens : frame_lenses[f]) {
          const fs::path path = tmp / "images" / lens.name;
          halves.push_back(cv::imread(path.string(), cv::IMREAD_COLOR));
          if (halves.back().empty()) return "cannot read back " + path.string();
        }
        cv::Mat raw;
        cv::hconcat(halves, raw);
        const std::string name = FrameName(static_cast<int>(f), options.image_extension);
        const fs::path path = tmp / "raw" / name;
        if (!cv::imwrite(path.string(), raw,
                         ImageWriteParams(name, options.dataset.effects.jpeg_quality))) {
          return "cannot write " + path.string();
        }
      }
      if (extra_log) *extra_log << "wrote " << frames.size() << " raw side-by-side frames\n";
    }

    if (options.stitched) {
      std::vector<VirtualCamera> panoramas;
      for (size_t f = 0; f < frames.size(); ++f) {
        auto spec = std::make_shared<StitchSpec>();
        spec->lenses = frame_lenses[f];
        spec->band_deg = options.stitch_band_deg;
        spec->distance_m = options.stitch_distance_m;
        Eigen::Vector3d centre = Eigen::Vector3d::Zero();
        for (const VirtualCamera& lens : frame_lenses[f]) centre += lens.CentreInWorld();
        centre /= static_cast<double>(frame_lenses[f].size());
        const Eigen::Matrix3d world_from_rig =
            frames[f].rig_from_world_rotation.conjugate().toRotationMatrix();
        const int width = options.stitched_width, height = width / 2;
        VirtualCamera panorama =
            MakeCamera(FrameName(static_cast<int>(f), options.image_extension), "EQUIRECTANGULAR",
                       width, height, {static_cast<double>(width), static_cast<double>(height)},
                       world_from_rig, centre);
        panorama.stitch = spec;
        panoramas.push_back(panorama);
      }
      // The stitcher's output is drawn from ideal lenses; of the sensor
      // effects only the noise and the JPEG quality apply to it.
      DatasetOptions stitched_options;
      stitched_options.render = options.dataset.render;
      stitched_options.effects.noise_sigma = options.dataset.effects.noise_sigma;
      stitched_options.effects.jpeg_quality = options.dataset.effects.jpeg_quality;
      stitched_options.effects.seed = options.dataset.effects.seed;
      if (extra_log) *extra_log << "stitching " << panoramas.size() << " panoramas\n";
      error = WriteDataset((tmp / "stitched").string(), scene, panoramas, stitched_options,
                           extra_log);
      if (!error.empty()) return "stitched panoramas: " + error;
    }
    return "";
  };
  return WriteDataset(output_dir, scene, cameras, dataset, log);
}

}  // namespace synthetic
}  // namespace sphera
