#include "colmap_ext/exe/rig_calibration.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/estimators/solvers/similarity_transform.h"
#include "colmap/geometry/sim3.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/util/file.h"
#include "colmap/util/logging.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace colmap {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

double AngleDeg(const Eigen::Quaterniond& q) {
  return 2 * std::atan2(q.vec().norm(), std::abs(q.w())) * kRadToDeg;
}

// Pixels on a grid over the disc of radius `fraction * min(w, h)` around
// the principal point (the image centre for models without one).
std::vector<Eigen::Vector2d> DiscPixels(const Camera& camera, double fraction) {
  Eigen::Vector2d centre(camera.width / 2.0, camera.height / 2.0);
  if (!camera.PrincipalPointIdxs().empty()) {
    centre = Eigen::Vector2d(camera.PrincipalPointX(), camera.PrincipalPointY());
  }
  const double radius = fraction * std::min(camera.width, camera.height);
  const double step = std::max(1.0, radius / 64);
  std::vector<Eigen::Vector2d> pixels;
  for (double y = -radius; y <= radius; y += step) {
    for (double x = -radius; x <= radius; x += step) {
      if (x * x + y * y <= radius * radius) pixels.push_back(centre + Eigen::Vector2d(x, y));
    }
  }
  return pixels;
}

// Twice the largest angle between the optical axis and the rays of the disc.
double FieldOfViewDeg(const Camera& camera, double fraction) {
  double max_angle = 0;
  for (const Eigen::Vector2d& pixel : DiscPixels(camera, fraction)) {
    const std::optional<Eigen::Vector3d> ray = camera.CamRayFromImg(pixel);
    if (ray) {
      max_angle = std::max(max_angle, std::acos(std::clamp(ray->normalized().z(), -1.0, 1.0)));
    }
  }
  return 2 * max_angle * kRadToDeg;
}

// Pixels per radian along x and along y at the optical axis: the focal
// length a lens has whatever its model, comparable across models and
// identifiable where a model's parameters trade off (UNIFIED_OMNI's focal
// length and xi give the same projection along a curve: its axis focal is
// fx / (1 + xi)). Central differences of the projection over +-1e-4 rad.
Eigen::Vector2d AxisFocal(const Camera& camera) {
  constexpr double kAngle = 1e-4;
  Eigen::Vector2d focal = Eigen::Vector2d::Constant(
      std::numeric_limits<double>::quiet_NaN());
  for (int axis = 0; axis < 2; ++axis) {
    Eigen::Vector3d plus(0, 0, std::cos(kAngle));
    Eigen::Vector3d minus = plus;
    plus(axis) = std::sin(kAngle);
    minus(axis) = -std::sin(kAngle);
    const std::optional<Eigen::Vector2d> a = camera.ImgFromCam(plus, false);
    const std::optional<Eigen::Vector2d> b = camera.ImgFromCam(minus, false);
    if (a && b) focal(axis) = (*a - *b)(axis) / (2 * kAngle);
  }
  return focal;
}

// The folder of a camera's images ("lens0" of "lens0/frame000.jpg"), or the
// camera id when its images have no folder.
std::map<camera_t, std::string> CameraFolders(const Reconstruction& reconstruction) {
  std::map<camera_t, std::string> folders;
  for (const auto& [image_id, image] : reconstruction.Images()) {
    const size_t slash = image.Name().find_last_of('/');
    folders.emplace(image.CameraId(), slash == std::string::npos
                                          ? "camera" + std::to_string(image.CameraId())
                                          : image.Name().substr(0, slash));
  }
  return folders;
}

std::string JsonList(const std::vector<double>& values) {
  std::ostringstream out;
  out << std::setprecision(17) << "[";
  for (size_t i = 0; i < values.size(); ++i) out << (i ? ", " : "") << values[i];
  out << "]";
  return out.str();
}

void WriteFileAtomically(const std::string& path, const std::string& text) {
  const std::string tmp_path = path + ".tmp";
  {
    std::ofstream file(tmp_path, std::ios::trunc);
    THROW_CHECK_FILE_OPEN(file, tmp_path);
    file << text;
    if (!file) throw std::runtime_error("cannot write " + tmp_path);
  }
  if (std::rename(tmp_path.c_str(), path.c_str()) != 0) {
    throw std::runtime_error("cannot rename " + tmp_path + " to " + path);
  }
}

struct LensReport {
  camera_t camera_id = kInvalidCameraId;
  std::string name;
  bool reference = false;
  Camera camera;
  double fov_deg = 0;
  std::optional<Rigid3d> sensor_from_rig;
  // With ground truth.
  Eigen::Vector2d axis_focal = Eigen::Vector2d::Zero();
  std::optional<double> projection_median_px, projection_max_px, focal_ratio,
      axis_focal_ratio;
  std::optional<double> rotation_error_deg, centre_error;
};

}  // namespace

int RunRigCalibration(int argc, char** argv) {
  std::string input_path;
  std::string gt_path;
  std::string output_path;
  double radius_fraction = 0.5;

  OptionManager options;
  options.AddRequiredOption("input_path", &input_path);
  options.AddDefaultOption("gt_path", &gt_path);
  options.AddDefaultOption("output_path", &output_path);
  options.AddDefaultOption("radius_fraction", &radius_fraction,
                           "Field of view and projection differences over the disc of this "
                           "fraction of min(width, height) around the principal point.");
  if (!options.Parse(argc, argv)) {
    return EXIT_FAILURE;
  }
  if (!(radius_fraction > 0 && radius_fraction <= 1)) {
    LOG(ERROR) << "radius_fraction must be in (0, 1] (got " << radius_fraction << ")";
    return EXIT_FAILURE;
  }
  for (const auto& [name, path] : {std::make_pair("input_path", input_path),
                                   std::make_pair("gt_path", gt_path),
                                   std::make_pair("output_path", output_path)}) {
    if (!path.empty() && !ExistsDir(path)) {
      LOG(ERROR) << name << ": " << path << " is not a directory";
      return EXIT_FAILURE;
    }
  }

  Reconstruction model;
  model.Read(input_path);
  std::optional<Reconstruction> gt;
  std::optional<Sim3d> gt_from_model;
  std::map<std::string, image_t> gt_images;
  if (!gt_path.empty()) {
    gt.emplace();
    gt->Read(gt_path);
    for (const auto& [image_id, image] : gt->Images()) gt_images[image.Name()] = image_id;
    std::vector<Eigen::Vector3d> src, tgt;
    for (const image_t image_id : model.RegImageIds()) {
      const Image& image = model.Image(image_id);
      const auto it = gt_images.find(image.Name());
      if (it == gt_images.end() || !gt->Image(it->second).HasPose()) continue;
      src.push_back(image.ProjectionCenter());
      tgt.push_back(gt->Image(it->second).ProjectionCenter());
    }
    Sim3d sim;
    if (src.size() < 3 || !EstimateSim3d(src, tgt, sim)) {
      LOG(ERROR) << "gt_path: fewer than 3 images of " << input_path
                 << " have a ground-truth pose to align with";
      return EXIT_FAILURE;
    }
    gt_from_model = sim;
  }

  const std::map<camera_t, std::string> folders = CameraFolders(model);
  std::ostringstream table, json, config;
  json << std::setprecision(10) << "{\n  \"rigs\": [";
  config << std::setprecision(17) << "[";
  table << std::fixed;
  size_t num_rigs = 0;
  for (const auto& [rig_id, rig] : model.Rigs()) {
    if (rig.NumSensors() < 2) continue;
    std::vector<LensReport> lenses;
    auto add = [&](const sensor_t& sensor_id, const std::optional<Rigid3d>& pose, bool ref) {
      if (sensor_id.type != SensorType::CAMERA) return;
      LensReport lens;
      lens.camera_id = sensor_id.id;
      lens.camera = model.Camera(sensor_id.id);
      const auto folder = folders.find(sensor_id.id);
      lens.name = folder != folders.end() ? folder->second : "camera" + std::to_string(sensor_id.id);
      lens.reference = ref;
      lens.fov_deg = FieldOfViewDeg(lens.camera, radius_fraction);
      lens.axis_focal = AxisFocal(lens.camera);
      lens.sensor_from_rig = pose;
      lenses.push_back(lens);
    };
    add(rig.RefSensorId(), Rigid3d(), true);
    for (const auto& [sensor_id, pose] : rig.NonRefSensors()) add(sensor_id, pose, false);

    if (gt) {
      // The ground truth's camera and sensor_from_rig of every lens, by the
      // name of one of its images.
      for (LensReport& lens : lenses) {
        std::optional<camera_t> gt_camera_id;
        for (const auto& [image_id, image] : model.Images()) {
          if (image.CameraId() != lens.camera_id) continue;
          const auto it = gt_images.find(image.Name());
          if (it != gt_images.end()) {
            gt_camera_id = gt->Image(it->second).CameraId();
            break;
          }
        }
        if (!gt_camera_id) continue;
        const Camera& gt_camera = gt->Camera(*gt_camera_id);
        std::vector<double> distances;
        for (const Eigen::Vector2d& pixel : DiscPixels(gt_camera, radius_fraction)) {
          const std::optional<Eigen::Vector3d> ray = gt_camera.CamRayFromImg(pixel);
          if (!ray) continue;
          const std::optional<Eigen::Vector2d> projected = lens.camera.ImgFromCam(*ray, false);
          if (projected) distances.push_back((*projected - pixel).norm());
        }
        if (!distances.empty()) {
          std::sort(distances.begin(), distances.end());
          lens.projection_median_px = distances[distances.size() / 2];
          lens.projection_max_px = distances.back();
        }
        if (!gt_camera.FocalLengthIdxs().empty() && !lens.camera.FocalLengthIdxs().empty()) {
          lens.focal_ratio = lens.camera.MeanFocalLength() / gt_camera.MeanFocalLength();
        }
        if (const double gt_focal = AxisFocal(gt_camera).mean(); std::isfinite(gt_focal) &&
            std::isfinite(lens.axis_focal.mean())) {
          lens.axis_focal_ratio = lens.axis_focal.mean() / gt_focal;
        }
        for (const auto& [gt_rig_id, gt_rig] : gt->Rigs()) {
          const sensor_t gt_sensor(SensorType::CAMERA, *gt_camera_id);
          if (!gt_rig.HasSensor(gt_sensor)) continue;
          const Rigid3d gt_pose = gt_rig.IsRefSensor(gt_sensor) ? Rigid3d()
                                  : gt_rig.HasSensorFromRig(gt_sensor)
                                      ? gt_rig.SensorFromRig(gt_sensor)
                                      : Rigid3d();
          if (!lens.sensor_from_rig) break;
          lens.rotation_error_deg =
              AngleDeg(gt_pose.rotation() * lens.sensor_from_rig->rotation().inverse());
          const Eigen::Vector3d centre = gt_from_model->scale() *
                                         (lens.sensor_from_rig->rotation().inverse() *
                                          -lens.sensor_from_rig->translation());
          const Eigen::Vector3d gt_centre = gt_pose.rotation().inverse() * -gt_pose.translation();
          lens.centre_error = (centre - gt_centre).norm();
          break;
        }
      }
    }

    const double scale = gt_from_model ? gt_from_model->scale() : 1.0;
    table << "Rig " << rig_id << ": " << lenses.size() << " lenses, reference "
          << lenses.front().name << (gt ? " (lengths in the ground truth's units)" : "")
          << "\n";
    json << (num_rigs ? "," : "") << "\n    {\"rig_id\": " << rig_id << ", \"lenses\": [";
    config << (num_rigs ? "," : "") << "\n  {\n    \"cameras\": [";
    for (size_t k = 0; k < lenses.size(); ++k) {
      const LensReport& lens = lenses[k];
      const Camera& camera = lens.camera;
      table << "  " << lens.name << " (camera " << lens.camera_id << ", " << camera.ModelName()
            << " " << camera.width << "x" << camera.height << "): field of view "
            << std::setprecision(1) << lens.fov_deg << " deg";
      if (!camera.FocalLengthIdxs().empty()) {
        table << std::setprecision(2) << ", focal " << camera.FocalLengthX();
        if (camera.FocalLengthIdxs().size() > 1) {
          table << " x " << camera.FocalLengthY() << " (fx/fy " << std::setprecision(5)
                << camera.FocalLengthX() / camera.FocalLengthY() << ")";
        }
      }
      if (lens.axis_focal.allFinite()) {
        table << std::setprecision(2) << ", on the axis " << lens.axis_focal.x() << " x "
              << lens.axis_focal.y() << " px/rad";
      }
      table << std::setprecision(6) << ", params " << camera.ParamsToString() << "\n";
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      double angle = 0;
      if (lens.sensor_from_rig) {
        centre = scale * (lens.sensor_from_rig->rotation().inverse() *
                          -lens.sensor_from_rig->translation());
        angle = AngleDeg(lens.sensor_from_rig->rotation());
        table << "    pose in the rig: turned " << std::setprecision(3) << angle
              << " deg from " << lenses.front().name << ", centre (" << std::setprecision(5)
              << centre.x() << ", " << centre.y() << ", " << centre.z() << "), "
              << centre.norm() << " from it\n";
      } else {
        table << "    pose in the rig: unknown\n";
      }
      if (lens.projection_max_px) {
        table << "    vs ground truth: projection differs by " << std::setprecision(3)
              << *lens.projection_median_px << " px (median), " << *lens.projection_max_px
              << " px (max)";
        if (lens.focal_ratio) table << std::setprecision(5) << ", focal ratio " << *lens.focal_ratio;
        if (lens.axis_focal_ratio) {
          table << std::setprecision(5) << ", on the axis " << *lens.axis_focal_ratio;
        }
        if (lens.rotation_error_deg) {
          table << std::setprecision(4) << ", rotation error " << *lens.rotation_error_deg
                << " deg, centre error " << std::setprecision(6) << *lens.centre_error;
        }
        table << "\n";
      }
      auto optional_number = [](const std::optional<double>& value) {
        std::ostringstream out;
        out << std::setprecision(10);
        if (value) {
          out << *value;
        } else {
          out << "null";
        }
        return out.str();
      };
      json << (k ? "," : "") << "\n      {\"name\": \"" << lens.name << "\", \"camera_id\": "
           << lens.camera_id << ", \"reference\": " << (lens.reference ? "true" : "false")
           << ", \"model\": \"" << camera.ModelName() << "\", \"params\": "
           << JsonList(camera.params) << ", \"field_of_view_deg\": " << lens.fov_deg
           << ", \"rotation_from_reference_deg\": " << angle
           << ", \"centre_in_rig\": " << JsonList({centre.x(), centre.y(), centre.z()})
           << ", \"projection_median_px\": " << optional_number(lens.projection_median_px)
           << ", \"projection_max_px\": " << optional_number(lens.projection_max_px)
           << ", \"focal_ratio\": " << optional_number(lens.focal_ratio)
           << ", \"axis_focal\": "
           << (lens.axis_focal.allFinite()
                   ? JsonList({lens.axis_focal.x(), lens.axis_focal.y()})
                   : "null")
           << ", \"axis_focal_ratio\": " << optional_number(lens.axis_focal_ratio)
           << ", \"rotation_error_deg\": " << optional_number(lens.rotation_error_deg)
           << ", \"centre_error\": " << optional_number(lens.centre_error) << "}";
      config << (k ? "," : "") << "\n      {\n        \"image_prefix\": \"" << lens.name
             << "/\",\n";
      if (lens.reference) {
        config << "        \"ref_sensor\": true,\n";
      } else if (lens.sensor_from_rig) {
        const Eigen::Quaterniond& q = lens.sensor_from_rig->rotation();
        const Eigen::Vector3d t = scale * lens.sensor_from_rig->translation();
        config << "        \"cam_from_rig_rotation\": " << JsonList({q.w(), q.x(), q.y(), q.z()})
               << ",\n        \"cam_from_rig_translation\": " << JsonList({t.x(), t.y(), t.z()})
               << ",\n";
      }
      config << "        \"camera_model_name\": \"" << camera.ModelName() << "\",\n"
             << "        \"camera_params\": " << JsonList(camera.params) << "\n      }";
    }
    json << "\n    ]}";
    config << "\n    ]\n  }";
    ++num_rigs;
  }
  json << "\n  ]\n}\n";
  config << "\n]\n";
  if (num_rigs == 0) {
    LOG(ERROR) << input_path << " has no rig of more than one sensor (configure one with "
               << "rig_configurator before mapping)";
    return EXIT_FAILURE;
  }
  std::cout << table.str() << std::flush;
  if (!output_path.empty()) {
    WriteFileAtomically((std::filesystem::path(output_path) / "rig_config.json").string(),
                        config.str());
    WriteFileAtomically((std::filesystem::path(output_path) / "rig_calibration.json").string(),
                        json.str());
  }
  return EXIT_SUCCESS;
}

}  // namespace colmap
