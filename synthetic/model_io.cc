#include "synthetic/model_io.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>

#include "camera_models/registry.h"

namespace sphera {
namespace synthetic {
namespace {

namespace fs = std::filesystem;

// Rotation about world axis `axis` by `angle` radians.
Eigen::Matrix3d AxisRotation(int axis, double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::Unit(axis)).toRotationMatrix();
}

// world_from_cam for a camera heading `yaw` about the vertical (yaw 0 looks
// along +Z, yaw pi/2 along +X), then pitch about its x axis and roll about
// its z axis. The world's vertical is the camera's y axis, so identity is an
// upright camera.
Eigen::Matrix3d WorldFromCam(double yaw, double pitch, double roll) {
  return AxisRotation(1, yaw) * AxisRotation(0, pitch) * AxisRotation(2, roll);
}

std::string Join(const std::vector<double>& values) {
  std::ostringstream out;
  out << std::setprecision(17);
  for (size_t i = 0; i < values.size(); ++i) out << (i ? " " : "") << values[i];
  return out.str();
}

std::string ImageName(int index, const std::string& extension) {
  std::ostringstream name;
  name << "cam" << std::setw(3) << std::setfill('0') << index << extension;
  return name.str();
}

}  // namespace

std::vector<double> DefaultParams(const std::string& model_name, int width, int height,
                                  std::string* error) {
  error->clear();
  const double w = width, h = height, cx = w / 2, cy = h / 2;
  const double m = std::min(w, h);
  if (model_name == "EQUIRECTANGULAR") return {w, h};
  if (model_name == "PINHOLE") return {w / 2, w / 2, cx, cy};
  if (model_name == "SIMPLE_PINHOLE") return {w / 2, cx, cy};
  if (model_name == "OPENCV") return {w / 2, w / 2, cx, cy, -0.05, 0.01, 0.0005, -0.0005};
  // Focal lengths from each model's projection radius at 95 degrees
  // (x = sin 95deg, z = cos 95deg) so that it lands at 0.48 * m.
  if (model_name == "EUCM") return {0.272 * m, 0.272 * m, cx, cy, 0.6, 1.0};
  if (model_name == "UNIFIED_OMNI") return {0.44 * m, 0.44 * m, cx, cy, 1.0, 0, 0, 0, 0};
  if (model_name == "DOUBLE_SPHERE") return {0.244 * m, 0.244 * m, cx, cy, -0.2, 0.6};
  if (ModelIdFromName(model_name) < 0) {
    *error = "unknown camera model '" + model_name + "'";
  } else {
    *error = "no default parameters for model " + model_name + ": pass --camera_params";
  }
  return {};
}

bool ParseParamList(const std::string& text, std::vector<double>* values) {
  values->clear();
  std::string spaced = text;
  std::replace(spaced.begin(), spaced.end(), ',', ' ');
  std::istringstream in(spaced);
  std::string token;
  while (in >> token) {
    try {
      size_t used = 0;
      const double value = std::stod(token, &used);
      if (used != token.size()) return false;
      values->push_back(value);
    } catch (const std::exception&) {
      return false;
    }
  }
  return true;
}

std::string MakeLayout(const LayoutOptions& options, std::vector<VirtualCamera>* cameras) {
  cameras->clear();
  std::mt19937_64 rng(options.seed ^ 0x6c61796f7574ULL);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double deg = M_PI / 180;

  std::string model = options.model_name;
  int width = options.width, height = options.height;
  const bool perspective_layout = options.layout == "ring";
  if (model.empty()) model = perspective_layout ? "PINHOLE" : "EQUIRECTANGULAR";
  if (width <= 0 || height <= 0) {
    if (width > 0 || height > 0) return "give both --width and --height";
    if (model == "EQUIRECTANGULAR") {
      width = 2048, height = 1024;
    } else if (perspective_layout || model == "PINHOLE" || model == "OPENCV" ||
               model == "SIMPLE_PINHOLE") {
      width = 640, height = 480;
    } else {
      width = 1024, height = 1024;
    }
  }
  std::vector<double> params = options.params;
  if (params.empty()) {
    std::string error;
    params = DefaultParams(model, width, height, &error);
    if (!error.empty()) return error;
  }

  struct Pose {
    Eigen::Matrix3d world_from_cam;
    Eigen::Vector3d centre;
  };
  std::vector<Pose> poses;
  if (options.layout == "room9") {
    if (options.num_cameras != 0 && options.num_cameras != 9) {
      return "layout room9 has exactly 9 cameras (got --num_cameras " +
             std::to_string(options.num_cameras) + ")";
    }
    // 1.5 m above the floor is y = 0; +Y is down.
    for (int iz = -1; iz <= 1; ++iz) {
      for (int ix = -1; ix <= 1; ++ix) {
        const double yaw = 5 * deg * unit(rng), pitch = 5 * deg * unit(rng),
                     roll = 5 * deg * unit(rng);
        poses.push_back({WorldFromCam(yaw, pitch, roll), Eigen::Vector3d(ix, 0.0, iz)});
      }
    }
  } else if (options.layout == "ring") {
    const int n = options.num_cameras > 0 ? options.num_cameras : 16;
    if (n < 2) return "layout ring needs at least 2 cameras";
    for (int i = 0; i < n; ++i) {
      const double yaw = 2 * M_PI * i / n;
      const double height_offset = (i % 2 == 0) ? -0.1 : 0.1;
      const Eigen::Vector3d centre(0.6 * std::sin(yaw), height_offset, 0.6 * std::cos(yaw));
      poses.push_back({WorldFromCam(yaw + 2 * deg * unit(rng), 3 * deg * unit(rng),
                                    2 * deg * unit(rng)),
                       centre});
    }
  } else if (options.layout == "grid") {
    const int n = options.num_cameras > 0 ? options.num_cameras : 9;
    const int cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
    const int rows = (n + cols - 1) / cols;
    for (int i = 0; i < n; ++i) {
      const int r = i / cols, c = i % cols;
      const double x = cols > 1 ? -1.2 + 2.4 * c / (cols - 1) : 0.0;
      const double z = rows > 1 ? -1.2 + 2.4 * r / (rows - 1) : 0.0;
      poses.push_back({WorldFromCam(M_PI * unit(rng), 10 * deg * unit(rng), 10 * deg * unit(rng)),
                       Eigen::Vector3d(x, 0.2 * unit(rng), z)});
    }
  } else {
    return "unknown layout '" + options.layout + "' (expected room9, ring or grid)";
  }
  for (size_t i = 0; i < poses.size(); ++i) {
    cameras->push_back(MakeCamera(ImageName(static_cast<int>(i), options.image_extension), model,
                                  width, height, params, poses[i].world_from_cam,
                                  poses[i].centre));
  }
  return "";
}

std::string ForEachDataLine(
    const std::string& path,
    const std::function<std::string(const std::string& line, const std::string& where)>& parse) {
  std::ifstream file(path);
  if (!file) return "cannot read " + path;
  std::string line;
  int line_number = 0;
  while (std::getline(file, line)) {
    ++line_number;
    const size_t comment = line.find('#');
    if (comment != std::string::npos) line.resize(comment);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string error = parse(line, path + ":" + std::to_string(line_number) + ": ");
    if (!error.empty()) return error;
  }
  return "";
}

std::string ReadRigFile(const std::string& path, const std::string& default_extension,
                        std::vector<VirtualCamera>* cameras) {
  cameras->clear();
  const std::string error = ForEachDataLine(path, [&](const std::string& line,
                                                      const std::string& where) -> std::string {
    const size_t bar = line.find('|');
    if (bar == std::string::npos) {
      return where + "expected 'NAME MODEL WIDTH HEIGHT PARAMS... | QW QX QY QZ TX TY TZ'";
    }
    std::istringstream head(line.substr(0, bar));
    std::string name, model, width_text, height_text;
    if (!(head >> name >> model >> width_text >> height_text)) {
      return where + "expected NAME MODEL WIDTH HEIGHT before '|'";
    }
    if (!IsJpegFileName(name) && !IsPngFileName(name)) name += default_extension;
    const std::string camera = where + "camera '" + name + "': ";
    int width = 0, height = 0;
    try {
      size_t used_w = 0, used_h = 0;
      width = std::stoi(width_text, &used_w);
      height = std::stoi(height_text, &used_h);
      if (used_w != width_text.size() || used_h != height_text.size()) throw std::exception();
    } catch (const std::exception&) {
      return camera + "bad WIDTH/HEIGHT '" + width_text + " " + height_text + "'";
    }
    std::string rest;
    std::getline(head, rest);
    std::vector<double> params, pose;
    if (!ParseParamList(rest, &params)) return camera + "malformed parameter list";
    if (!ParseParamList(line.substr(bar + 1), &pose) || pose.size() != 7) {
      return camera + "expected 7 numbers after '|': QW QX QY QZ TX TY TZ";
    }
    VirtualCamera cam;
    cam.name = name;
    cam.model_name = model;
    cam.model_id = ModelIdFromName(model);
    cam.width = width;
    cam.height = height;
    cam.params = params;
    Eigen::Quaterniond q(pose[0], pose[1], pose[2], pose[3]);
    if (!(q.norm() > 1e-12)) return camera + "zero quaternion";
    q.normalize();
    cam.cam_from_world_rotation = q;
    cam.cam_from_world_translation = Eigen::Vector3d(pose[4], pose[5], pose[6]);
    const std::string error = cam.Check();
    if (!error.empty()) return where + error;
    cameras->push_back(cam);
    return "";
  });
  if (!error.empty()) return error;
  if (cameras->empty()) return "rig file " + path + " has no cameras";
  return "";
}

std::string CheckCameras(const Scene& scene, const std::vector<VirtualCamera>& cameras) {
  if (cameras.empty()) return "no cameras";
  std::set<std::string> names;
  for (const VirtualCamera& camera : cameras) {
    const std::string error = camera.Check();
    if (!error.empty()) return error;
    if (!names.insert(camera.name).second) return "camera '" + camera.name + "': duplicate name";
    const Eigen::Vector3d centre = camera.CentreInWorld();
    if (!scene.IsFreeSpace(centre)) {
      std::ostringstream error_message;
      error_message << "camera '" << camera.name << "': centre (" << centre.transpose()
                    << ") is not in the free space of the room (x, z in [-2, 2], y in "
                       "[-1.5, 1.5], outside the boxes)";
      return error_message.str();
    }
  }
  return "";
}

std::vector<GroundTruthPoint> SamplePoints(const Scene& scene,
                                           const std::vector<VirtualCamera>& cameras,
                                           int num_points, uint64_t seed) {
  std::vector<GroundTruthPoint> points;
  std::mt19937_64 rng(seed ^ 0x706f696e7473ULL);
  const int64_t max_attempts = 100LL * std::max(num_points, 1);
  for (int64_t attempt = 0;
       attempt < max_attempts && static_cast<int>(points.size()) < num_points; ++attempt) {
    const RayHit sample = scene.SampleSurfacePoint(&rng);
    GroundTruthPoint point;
    point.xyz = sample.point;
    for (size_t i = 0; i < cameras.size(); ++i) {
      const VirtualCamera& camera = cameras[i];
      const Eigen::Vector3d centre = camera.CentreInWorld();
      const Eigen::Vector3d to_point = point.xyz - centre;
      const double distance = to_point.norm();
      if (distance < 1e-6) continue;
      const Eigen::Vector3d ray_in_world = to_point / distance;
      // Unoccluded: the first surface along the ray is the point itself.
      RayHit hit;
      if (!scene.CastRay(centre, ray_in_world, &hit) ||
          std::abs(hit.range - distance) > 1e-7 * distance + 1e-9) {
        continue;
      }
      const Eigen::Vector3d ray_in_cam = camera.cam_from_world_rotation * ray_in_world;
      Eigen::Vector2d pixel;
      if (!ImageFromRay(camera.model_id, camera.params, ray_in_cam, &pixel)) continue;
      if (!(pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() < camera.width &&
            pixel.y() < camera.height) ||
          !camera.InImageCircle(static_cast<int>(pixel.x()), static_cast<int>(pixel.y()))) {
        continue;
      }
      Eigen::Vector3d back;
      if (!RayFromImage(camera.model_id, camera.params, pixel, &back)) continue;
      point.observations.push_back({static_cast<int>(i), pixel});
    }
    if (point.observations.size() < 2) continue;
    const Eigen::Vector3f colour = scene.Colour(sample.face_id, point.xyz);
    point.rgb = (255.0f * colour).array().round().cast<int>().matrix();
    points.push_back(point);
  }
  return points;
}

namespace {

// The stages of WriteDataset: check the inputs, open the staging directory,
// render every image through its lens and sensor and write it, sample the
// ground-truth points, write the model, move the staging directory in place.

std::string CheckDatasetInputs(const Scene& scene, const std::vector<VirtualCamera>& cameras,
                               const DatasetOptions& options) {
  std::string error = CheckCameras(scene, cameras);
  if (error.empty()) error = options.render.Check();
  if (error.empty()) error = scene.Options().Check();
  if (error.empty()) error = options.effects.Check();
  if (!error.empty()) return error;
  if (options.num_points < 0) return "--points must be >= 0";
  if (options.rig == nullptr) return "";
  const RigGroundTruth& rig = *options.rig;
  const size_t num_sensors = rig.sensor_names.size();
  if (num_sensors == 0 || rig.sensor_from_rig_rotation.size() != num_sensors ||
      rig.sensor_from_rig_translation.size() != num_sensors ||
      rig.rig_from_world_rotation.size() != rig.rig_from_world_translation.size() ||
      rig.image_sensor.size() != cameras.size() || rig.image_frame.size() != cameras.size()) {
    return "inconsistent rig description";
  }
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (rig.image_sensor[i] < 0 || rig.image_sensor[i] >= static_cast<int>(num_sensors) ||
        rig.image_frame[i] < 0 ||
        rig.image_frame[i] >= static_cast<int>(rig.rig_from_world_rotation.size())) {
      return "camera '" + cameras[i].name + "': sensor or frame out of range";
    }
  }
  return "";
}

// A dataset is written into `tmp` and renamed to `dir` when complete.
struct Staging {
  fs::path dir;
  fs::path tmp;
  bool dir_exists = false;
};

bool WritesMask(const VirtualCamera& camera, const DatasetOptions& options) {
  return options.write_masks || LensCircle(camera, options.effects).z() > 0;
}

std::string OpenStaging(const std::string& output_dir, const std::vector<VirtualCamera>& cameras,
                        const DatasetOptions& options, std::ostream* log, Staging* staging) {
  fs::path dir(output_dir);
  if (dir.empty()) return "no output directory given";
  if (!dir.has_filename()) dir = dir.parent_path();  // strip a trailing slash
  std::error_code ec;
  staging->dir = dir;
  staging->dir_exists = fs::exists(dir, ec);
  if (staging->dir_exists) {
    if (!fs::is_directory(dir, ec)) return "output " + dir.string() + " exists and is not a directory";
    if (!fs::is_empty(dir, ec)) {
      return "refusing to overwrite non-empty output directory " + dir.string() +
             " (choose a new directory or remove it)";
    }
  }
  const fs::path tmp = dir.string() + ".tmp";
  staging->tmp = tmp;
  if (fs::exists(tmp, ec)) {
    if (log) *log << "removing stale staging directory " << tmp.string() << "\n";
    fs::remove_all(tmp, ec);
    if (ec) return "cannot remove stale staging directory " + tmp.string() + ": " + ec.message();
  }
  for (const char* sub : {"images", "depth", "sparse_gt"}) {
    fs::create_directories(tmp / sub, ec);
    if (ec) return "cannot create " + (tmp / sub).string() + ": " + ec.message();
  }
  for (const VirtualCamera& camera : cameras) {
    const fs::path folder = fs::path(camera.name).parent_path();
    if (folder.empty()) continue;
    for (const char* sub : {"images", "depth", "masks"}) {
      if (std::string(sub) == "masks" && !WritesMask(camera, options)) continue;
      fs::create_directories(tmp / sub / folder, ec);
      if (ec) return "cannot create " + (tmp / sub / folder).string() + ": " + ec.message();
    }
  }
  return "";
}

std::string CloseStaging(const Staging& staging) {
  std::error_code ec;
  if (staging.dir_exists) {
    fs::remove(staging.dir, ec);  // empty, checked by OpenStaging
    if (ec) return "cannot replace empty directory " + staging.dir.string() + ": " + ec.message();
  }
  fs::rename(staging.tmp, staging.dir, ec);
  if (ec) {
    return "cannot rename " + staging.tmp.string() + " to " + staging.dir.string() + ": " +
           ec.message();
  }
  return "";
}

// Writer stage: one image (8-bit BGR) in the format its name asks for.
std::string WriteImage(const fs::path& path, const cv::Mat& image, int jpeg_quality) {
  bool ok = false;
  try {
    ok = cv::imwrite(path.string(), image, ImageWriteParams(path.string(), jpeg_quality));
  } catch (const cv::Exception& e) {
    return "cannot write " + path.string() + ": " + e.what();
  }
  return ok ? "" : "cannot write " + path.string();
}

// Scene, lens projection and sensor stages for every camera, each image
// written as soon as it is done (a dataset does not fit in memory).
std::string RenderAndWriteImages(const fs::path& tmp, const Scene& scene,
                                 const std::vector<VirtualCamera>& cameras,
                                 const DatasetOptions& options, std::ostream* log) {
  for (size_t i = 0; i < cameras.size(); ++i) {
    const VirtualCamera& camera = cameras[i];
    const auto start = std::chrono::steady_clock::now();
    const RenderedImage rendered = Render(scene, camera, options.render);
    // In a rig every lens (sensor) has its own response; else every image.
    const int lens_index = options.rig ? options.rig->image_sensor[i] : static_cast<int>(i);
    const cv::Mat image =
        ApplySensorEffects(rendered.radiance, camera, options.effects, lens_index, i);
    std::string error = WriteImage(tmp / "images" / camera.name, image,
                                   options.effects.jpeg_quality);
    if (!error.empty()) return error;
    if (WritesMask(camera, options)) {
      const fs::path mask_path = tmp / "masks" / (camera.name + ".png");
      std::error_code ec;
      fs::create_directories(mask_path.parent_path(), ec);
      if (ec || !cv::imwrite(mask_path.string(), ValidPixelMask(camera, options.effects))) {
        return "cannot write " + mask_path.string();
      }
    }
    const fs::path depth_path = tmp / "depth" / (camera.name + ".depth.bin");
    if (!WriteDepthMap(depth_path.string(), rendered.depth)) {
      return "cannot write " + depth_path.string();
    }
    if (log) {
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      *log << "[" << i + 1 << "/" << cameras.size() << "] " << camera.name << " ("
           << camera.model_name << " " << camera.width << "x" << camera.height << ") "
           << std::fixed << std::setprecision(2) << seconds << " s\n"
           << std::defaultfloat;
      log->flush();
    }
  }
  return "";
}

// Camera ids per image and cameras.txt: identical intrinsics share one
// camera id; in a rig, every sensor is its own camera (id = sensor index + 1).
std::vector<int> AssignCameraIds(const std::vector<VirtualCamera>& cameras,
                                 const RigGroundTruth* rig, std::string* cameras_txt) {
  std::map<std::string, int> camera_ids;
  std::vector<int> image_camera_id(cameras.size());
  std::ostringstream text;
  text << "# Camera list with one line of data per camera:\n"
       << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n";
  for (size_t i = 0; i < cameras.size(); ++i) {
    const VirtualCamera& camera = cameras[i];
    const std::string intrinsics = camera.model_name + " " + std::to_string(camera.width) + " " +
                                   std::to_string(camera.height) + " " + Join(camera.params);
    const std::string key = rig ? std::to_string(rig->image_sensor[i]) : intrinsics;
    auto it = camera_ids.find(key);
    if (it == camera_ids.end()) {
      const int id = rig ? rig->image_sensor[i] + 1 : static_cast<int>(camera_ids.size()) + 1;
      it = camera_ids.emplace(key, id).first;
      text << it->second << " " << intrinsics << "\n";
    }
    image_camera_id[i] = it->second;
  }
  *cameras_txt = text.str();
  return image_camera_id;
}

// The points' observations in COLMAP's cross-referenced form.
struct ObservationIndex {
  // Per image, its observations (POINT3D_ID, pixel) in POINT2D_IDX order.
  std::vector<std::vector<std::pair<int, Eigen::Vector2d>>> image_points;
  // Per point, its track (IMAGE_ID, POINT2D_IDX).
  std::vector<std::vector<std::pair<int, int>>> tracks;
};

ObservationIndex IndexObservations(const std::vector<GroundTruthPoint>& points,
                                   size_t num_images) {
  ObservationIndex index;
  index.image_points.resize(num_images);
  index.tracks.resize(points.size());
  for (size_t p = 0; p < points.size(); ++p) {
    for (const PointObservation& obs : points[p].observations) {
      index.tracks[p].emplace_back(obs.image_index + 1,
                                   static_cast<int>(index.image_points[obs.image_index].size()));
      index.image_points[obs.image_index].emplace_back(static_cast<int>(p) + 1, obs.pixel);
    }
  }
  return index;
}

std::string ImagesText(const std::vector<VirtualCamera>& cameras,
                       const std::vector<int>& image_camera_id, const ObservationIndex& index) {
  std::ostringstream text;
  text << std::setprecision(17);
  text << "# Image list with two lines of data per image:\n"
       << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
       << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n";
  for (size_t i = 0; i < cameras.size(); ++i) {
    const VirtualCamera& camera = cameras[i];
    const Eigen::Quaterniond& q = camera.cam_from_world_rotation;
    const Eigen::Vector3d& t = camera.cam_from_world_translation;
    text << i + 1 << " " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " " << t.x()
         << " " << t.y() << " " << t.z() << " " << image_camera_id[i] << " " << camera.name
         << "\n";
    const auto& observations = index.image_points[i];
    for (size_t k = 0; k < observations.size(); ++k) {
      text << (k ? " " : "") << observations[k].second.x() << " " << observations[k].second.y()
           << " " << observations[k].first;
    }
    text << "\n";
  }
  return text.str();
}

std::string RigFileText(const std::vector<VirtualCamera>& cameras) {
  std::ostringstream text;
  text << std::setprecision(17);
  text << "# NAME MODEL WIDTH HEIGHT PARAMS... | QW QX QY QZ TX TY TZ (cam_from_world)\n";
  for (const VirtualCamera& camera : cameras) {
    const Eigen::Quaterniond& q = camera.cam_from_world_rotation;
    const Eigen::Vector3d& t = camera.cam_from_world_translation;
    text << camera.name << " " << camera.model_name << " " << camera.width << " "
         << camera.height << " " << Join(camera.params) << " | " << q.w() << " " << q.x() << " "
         << q.y() << " " << q.z() << " " << t.x() << " " << t.y() << " " << t.z() << "\n";
  }
  return text.str();
}

std::string PointsText(const std::vector<GroundTruthPoint>& points, const ObservationIndex& index) {
  std::ostringstream text;
  text << std::setprecision(17);
  text << "# 3D point list with one line of data per point:\n"
       << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n";
  for (size_t p = 0; p < points.size(); ++p) {
    const GroundTruthPoint& point = points[p];
    text << p + 1 << " " << point.xyz.x() << " " << point.xyz.y() << " " << point.xyz.z() << " "
         << point.rgb.x() << " " << point.rgb.y() << " " << point.rgb.z() << " 0";
    for (const auto& [image_id, point2d_idx] : index.tracks[p]) {
      text << " " << image_id << " " << point2d_idx;
    }
    text << "\n";
  }
  return text.str();
}

// COLMAP 4 text: sensor type CAMERA, sensor id = camera id, data id = image id.
std::string RigsText(const RigGroundTruth& rig) {
  std::ostringstream text;
  text << std::setprecision(17);
  text << "# Rig calib list with one line of data per calib:\n"
       << "#   RIG_ID, NUM_SENSORS, REF_SENSOR_TYPE, REF_SENSOR_ID, SENSORS[] as "
          "(SENSOR_TYPE, SENSOR_ID, HAS_POSE, [QW, QX, QY, QZ, TX, TY, TZ])\n"
       << "1 " << rig.sensor_names.size() << " CAMERA 1";
  for (size_t k = 1; k < rig.sensor_names.size(); ++k) {
    const Eigen::Quaterniond& q = rig.sensor_from_rig_rotation[k];
    const Eigen::Vector3d& t = rig.sensor_from_rig_translation[k];
    text << " CAMERA " << k + 1 << " 1 " << q.w() << " " << q.x() << " " << q.y() << " " << q.z()
         << " " << t.x() << " " << t.y() << " " << t.z();
  }
  text << "\n";
  return text.str();
}

std::string FramesText(const RigGroundTruth& rig, const std::vector<int>& image_camera_id) {
  std::ostringstream text;
  text << std::setprecision(17);
  text << "# Frame list with one line of data per frame:\n"
       << "#   FRAME_ID, RIG_ID, RIG_FROM_WORLD[QW, QX, QY, QZ, TX, TY, TZ], "
          "NUM_DATA_IDS, DATA_IDS[] as (SENSOR_TYPE, SENSOR_ID, DATA_ID)\n";
  for (size_t f = 0; f < rig.rig_from_world_rotation.size(); ++f) {
    std::vector<size_t> members;
    for (size_t i = 0; i < rig.image_frame.size(); ++i) {
      if (rig.image_frame[i] == static_cast<int>(f)) members.push_back(i);
    }
    if (members.empty()) continue;
    const Eigen::Quaterniond& q = rig.rig_from_world_rotation[f];
    const Eigen::Vector3d& t = rig.rig_from_world_translation[f];
    text << f + 1 << " 1 " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " "
         << t.x() << " " << t.y() << " " << t.z() << " " << members.size();
    for (const size_t i : members) text << " CAMERA " << image_camera_id[i] << " " << i + 1;
    text << "\n";
  }
  return text.str();
}

// Model stage: the ground truth (sparse_gt/ and rig.txt) of the cameras and
// points. Returns the number of distinct cameras in `num_cameras`.
std::string WriteModel(const fs::path& tmp, const std::vector<VirtualCamera>& cameras,
                       const std::vector<GroundTruthPoint>& points, const RigGroundTruth* rig,
                       int* num_cameras) {
  std::string cameras_txt;
  const std::vector<int> image_camera_id = AssignCameraIds(cameras, rig, &cameras_txt);
  *num_cameras = static_cast<int>(
      std::set<int>(image_camera_id.begin(), image_camera_id.end()).size());
  const ObservationIndex index = IndexObservations(points, cameras.size());
  std::vector<std::pair<fs::path, std::string>> texts = {
      {tmp / "sparse_gt" / "cameras.txt", cameras_txt},
      {tmp / "sparse_gt" / "images.txt", ImagesText(cameras, image_camera_id, index)},
      {tmp / "sparse_gt" / "points3D.txt", PointsText(points, index)},
      {tmp / "rig.txt", RigFileText(cameras)},
  };
  if (rig != nullptr) {
    texts.emplace_back(tmp / "sparse_gt" / "rigs.txt", RigsText(*rig));
    texts.emplace_back(tmp / "sparse_gt" / "frames.txt", FramesText(*rig, image_camera_id));
  }
  for (const auto& [path, text] : texts) {
    std::ofstream file(path);
    file << text;
    file.close();
    if (!file) return "cannot write " + path.string();
  }
  return "";
}

}  // namespace

std::string WriteDataset(const std::string& output_dir, const Scene& scene,
                         const std::vector<VirtualCamera>& cameras,
                         const DatasetOptions& options, std::ostream* log) {
  std::string error = CheckDatasetInputs(scene, cameras, options);
  if (!error.empty()) return error;
  Staging staging;
  error = OpenStaging(output_dir, cameras, options, log, &staging);
  auto fail = [&](const std::string& message) {
    std::error_code ignored;
    if (!staging.tmp.empty()) fs::remove_all(staging.tmp, ignored);
    return message;
  };
  if (!error.empty()) return fail(error);

  error = RenderAndWriteImages(staging.tmp, scene, cameras, options, log);
  if (!error.empty()) return fail(error);

  const std::vector<GroundTruthPoint> points =
      options.num_points > 0 ? SamplePoints(scene, cameras, options.num_points, options.points_seed)
                             : std::vector<GroundTruthPoint>();
  int num_cameras = 0;
  error = WriteModel(staging.tmp, cameras, points, options.rig, &num_cameras);
  if (!error.empty()) return fail(error);

  if (options.extra) {
    error = options.extra(staging.tmp.string(), log);
    if (!error.empty()) return fail(error);
  }
  error = CloseStaging(staging);
  if (!error.empty()) return fail(error);
  if (log) {
    *log << "wrote " << cameras.size() << " images, " << num_cameras << " camera(s), "
         << points.size() << " points to " << staging.dir.string() << "\n";
  }
  return "";
}

}  // namespace synthetic
}  // namespace sphera
