#include "colmap_ext/controllers/rig_calibration.h"

#include "colmap_ext/controllers/model_evaluation.h"
#include "colmap_ext/util/file_output.h"
#include "estimators/rig_direction_check.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

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

std::string OptionalNumber(const std::optional<double>& value) {
  std::ostringstream out;
  out << std::setprecision(10);
  if (value) {
    out << *value;
  } else {
    out << "null";
  }
  return out.str();
}

// The ground truth's camera of `lens`, by the name of one of its images.
std::optional<camera_t> GroundTruthCamera(
    const Reconstruction& model, const Reconstruction& ground_truth,
    const std::map<std::string, image_t>& gt_images, camera_t camera_id) {
  for (const auto& [image_id, image] : model.Images()) {
    if (image.CameraId() != camera_id) continue;
    const auto it = gt_images.find(image.Name());
    if (it != gt_images.end()) {
      return ground_truth.Image(it->second).CameraId();
    }
  }
  return std::nullopt;
}

void CompareWithGroundTruth(const Reconstruction& ground_truth,
                            camera_t gt_camera_id, double scale,
                            double radius_fraction, LensCalibration* lens) {
  const Camera& gt_camera = ground_truth.Camera(gt_camera_id);
  std::vector<double> distances;
  for (const Eigen::Vector2d& pixel : DiscPixels(gt_camera, radius_fraction)) {
    const std::optional<Eigen::Vector3d> ray = gt_camera.CamRayFromImg(pixel);
    if (!ray) continue;
    const std::optional<Eigen::Vector2d> projected =
        lens->camera.ImgFromCam(*ray, false);
    if (projected) distances.push_back((*projected - pixel).norm());
  }
  if (!distances.empty()) {
    std::sort(distances.begin(), distances.end());
    lens->projection_median_px = distances[distances.size() / 2];
    lens->projection_max_px = distances.back();
  }
  if (!gt_camera.FocalLengthIdxs().empty() &&
      !lens->camera.FocalLengthIdxs().empty()) {
    lens->focal_ratio =
        lens->camera.MeanFocalLength() / gt_camera.MeanFocalLength();
  }
  if (const double gt_focal = AxisFocal(gt_camera).mean();
      std::isfinite(gt_focal) && std::isfinite(lens->axis_focal.mean())) {
    lens->axis_focal_ratio = lens->axis_focal.mean() / gt_focal;
  }
  const sensor_t gt_sensor(SensorType::CAMERA, gt_camera_id);
  for (const auto& [gt_rig_id, gt_rig] : ground_truth.Rigs()) {
    if (!gt_rig.HasSensor(gt_sensor)) continue;
    const Rigid3d gt_pose = gt_rig.IsRefSensor(gt_sensor) ? Rigid3d()
                            : gt_rig.HasSensorFromRig(gt_sensor)
                                ? gt_rig.SensorFromRig(gt_sensor)
                                : Rigid3d();
    if (!lens->sensor_from_rig) break;
    lens->rotation_error_deg = AngleDeg(
        gt_pose.rotation() * lens->sensor_from_rig->rotation().inverse());
    const Eigen::Vector3d centre =
        scale * (lens->sensor_from_rig->rotation().inverse() *
                 -lens->sensor_from_rig->translation());
    const Eigen::Vector3d gt_centre =
        gt_pose.rotation().inverse() * -gt_pose.translation();
    lens->centre_error = (centre - gt_centre).norm();
    break;
  }
}

}  // namespace

std::string RigCalibrationOptions::Check() const {
  if (!(radius_fraction > 0 && radius_fraction <= 1)) {
    return "--radius_fraction must be in (0, 1], got " +
           std::to_string(radius_fraction);
  }
  return "";
}

RigCalibrationReport CalibrateRigs(const Reconstruction& model,
                                   const Reconstruction* ground_truth,
                                   const RigCalibrationOptions& options) {
  if (const std::string error = options.Check(); !error.empty()) {
    throw std::invalid_argument(error);
  }
  RigCalibrationReport report;
  std::map<std::string, image_t> gt_images;
  if (ground_truth != nullptr) {
    report.with_ground_truth = true;
    for (const auto& [image_id, image] : ground_truth->Images()) {
      gt_images[image.Name()] = image_id;
    }
    try {
      report.scale = EvaluateModel(*ground_truth, model, {})
                         .gt_from_reconstruction.scale();
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(std::string("--gt_path: ") + error.what());
    }
  }

  const std::map<camera_t, std::string> folders = CameraFolders(model);
  for (const auto& [rig_id, rig] : model.Rigs()) {
    if (rig.NumSensors() < 2) continue;
    RigCalibration calibration;
    calibration.rig_id = rig_id;
    auto add = [&](const sensor_t& sensor_id,
                   const std::optional<Rigid3d>& pose, bool reference) {
      if (sensor_id.type != SensorType::CAMERA) return;
      LensCalibration lens;
      lens.camera_id = sensor_id.id;
      lens.camera = model.Camera(sensor_id.id);
      const auto folder = folders.find(sensor_id.id);
      lens.name = folder != folders.end()
                      ? folder->second
                      : "camera" + std::to_string(sensor_id.id);
      lens.reference = reference;
      lens.fov_deg = FieldOfViewDeg(lens.camera, options.radius_fraction);
      lens.axis_focal = AxisFocal(lens.camera);
      lens.sensor_from_rig = pose;
      if (pose) {
        lens.centre_in_rig = report.scale * (pose->rotation().inverse() *
                                             -pose->translation());
        lens.rotation_from_reference_deg = AngleDeg(pose->rotation());
        const Eigen::Vector2d axis = sphera::LensAxisAzimuthElevationDeg(
            pose->rotation().toRotationMatrix());
        lens.axis_azimuth_deg = axis.x();
        lens.axis_elevation_deg = axis.y();
      }
      if (ground_truth != nullptr) {
        if (const std::optional<camera_t> gt_camera_id = GroundTruthCamera(
                model, *ground_truth, gt_images, lens.camera_id)) {
          CompareWithGroundTruth(*ground_truth, *gt_camera_id, report.scale,
                                 options.radius_fraction, &lens);
        }
      }
      calibration.lenses.push_back(std::move(lens));
    };
    add(rig.RefSensorId(), Rigid3d(), true);
    for (const auto& [sensor_id, pose] : rig.NonRefSensors()) {
      add(sensor_id, pose, false);
    }
    report.rigs.push_back(std::move(calibration));
  }
  if (report.rigs.empty()) {
    throw std::invalid_argument(
        "the model has no rig of more than one sensor (configure one with "
        "rig_configurator before mapping)");
  }
  return report;
}

std::string RigCalibrationText(const RigCalibrationReport& report) {
  std::ostringstream table;
  table << std::fixed;
  for (const RigCalibration& rig : report.rigs) {
    table << "Rig " << rig.rig_id << ": " << rig.lenses.size()
          << " lenses, reference " << rig.lenses.front().name
          << (report.with_ground_truth
                  ? " (lengths in the ground truth's units)"
                  : " (lengths in the model's units: the mapper scales a rig "
                    "model so that its lens offsets are on average the rig "
                    "config's)")
          << "\n";
    for (const LensCalibration& lens : rig.lenses) {
      const Camera& camera = lens.camera;
      table << "  " << lens.name << " (camera " << lens.camera_id << ", "
            << camera.ModelName() << " " << camera.width << "x"
            << camera.height << "): field of view " << std::setprecision(1)
            << lens.fov_deg << " deg";
      if (!camera.FocalLengthIdxs().empty()) {
        table << std::setprecision(2) << ", focal " << camera.FocalLengthX();
        if (camera.FocalLengthIdxs().size() > 1) {
          table << " x " << camera.FocalLengthY() << " (fx/fy "
                << std::setprecision(5)
                << camera.FocalLengthX() / camera.FocalLengthY() << ")";
        }
      }
      if (lens.axis_focal.allFinite()) {
        table << std::setprecision(2) << ", on the axis "
              << lens.axis_focal.x() << " x " << lens.axis_focal.y()
              << " px/rad";
      }
      table << std::setprecision(6) << ", params "
            << camera.ParamsToString() << "\n";
      if (lens.sensor_from_rig) {
        const Eigen::Vector3d& centre = lens.centre_in_rig;
        table << "    pose in the rig: turned " << std::setprecision(3)
              << lens.rotation_from_reference_deg << " deg from "
              << rig.lenses.front().name;
        if (!lens.reference) {
          table << " (its axis at azimuth " << std::setprecision(2)
                << lens.axis_azimuth_deg << " deg, elevation "
                << lens.axis_elevation_deg << " deg)";
        }
        table << ", centre ("
              << std::setprecision(5) << centre.x() << ", " << centre.y()
              << ", " << centre.z() << "), " << centre.norm()
              << " from it\n";
      } else {
        table << "    pose in the rig: unknown\n";
      }
      if (lens.projection_max_px) {
        table << "    vs ground truth: projection differs by "
              << std::setprecision(3) << *lens.projection_median_px
              << " px (median), " << *lens.projection_max_px << " px (max)";
        if (lens.focal_ratio) {
          table << std::setprecision(5) << ", focal ratio "
                << *lens.focal_ratio;
        }
        if (lens.axis_focal_ratio) {
          table << std::setprecision(5) << ", on the axis "
                << *lens.axis_focal_ratio;
        }
        if (lens.rotation_error_deg) {
          table << std::setprecision(4) << ", rotation error "
                << *lens.rotation_error_deg << " deg, centre error "
                << std::setprecision(6) << *lens.centre_error;
        }
        table << "\n";
      }
    }
  }
  return table.str();
}

std::string RigCalibrationJson(const RigCalibrationReport& report) {
  std::ostringstream json;
  json << std::setprecision(10) << "{\n  \"rigs\": [";
  for (size_t r = 0; r < report.rigs.size(); ++r) {
    const RigCalibration& rig = report.rigs[r];
    json << (r ? "," : "") << "\n    {\"rig_id\": " << rig.rig_id
         << ", \"lenses\": [";
    for (size_t k = 0; k < rig.lenses.size(); ++k) {
      const LensCalibration& lens = rig.lenses[k];
      const Eigen::Vector3d& centre = lens.centre_in_rig;
      json << (k ? "," : "") << "\n      {\"name\": \"" << lens.name
           << "\", \"camera_id\": " << lens.camera_id
           << ", \"reference\": " << (lens.reference ? "true" : "false")
           << ", \"model\": \"" << lens.camera.ModelName()
           << "\", \"params\": " << JsonList(lens.camera.params)
           << ", \"field_of_view_deg\": " << lens.fov_deg
           << ", \"rotation_from_reference_deg\": "
           << lens.rotation_from_reference_deg
           << ", \"axis_azimuth_deg\": " << lens.axis_azimuth_deg
           << ", \"axis_elevation_deg\": " << lens.axis_elevation_deg
           << ", \"centre_in_rig\": "
           << JsonList({centre.x(), centre.y(), centre.z()})
           << ", \"projection_median_px\": "
           << OptionalNumber(lens.projection_median_px)
           << ", \"projection_max_px\": "
           << OptionalNumber(lens.projection_max_px)
           << ", \"focal_ratio\": " << OptionalNumber(lens.focal_ratio)
           << ", \"axis_focal\": "
           << (lens.axis_focal.allFinite()
                   ? JsonList({lens.axis_focal.x(), lens.axis_focal.y()})
                   : "null")
           << ", \"axis_focal_ratio\": "
           << OptionalNumber(lens.axis_focal_ratio)
           << ", \"rotation_error_deg\": "
           << OptionalNumber(lens.rotation_error_deg)
           << ", \"centre_error\": " << OptionalNumber(lens.centre_error)
           << "}";
    }
    json << "\n    ]}";
  }
  json << "\n  ]\n}\n";
  return json.str();
}

std::string RigConfigJson(const RigCalibrationReport& report) {
  std::ostringstream config;
  config << std::setprecision(17) << "[";
  for (size_t r = 0; r < report.rigs.size(); ++r) {
    config << (r ? "," : "") << "\n  {\n    \"cameras\": [";
    const std::vector<LensCalibration>& lenses = report.rigs[r].lenses;
    for (size_t k = 0; k < lenses.size(); ++k) {
      const LensCalibration& lens = lenses[k];
      config << (k ? "," : "") << "\n      {\n        \"image_prefix\": \""
             << lens.name << "/\",\n";
      if (lens.reference) {
        config << "        \"ref_sensor\": true,\n";
      } else if (lens.sensor_from_rig) {
        const Eigen::Quaterniond& q = lens.sensor_from_rig->rotation();
        const Eigen::Vector3d t =
            report.scale * lens.sensor_from_rig->translation();
        config << "        \"cam_from_rig_rotation\": "
               << JsonList({q.w(), q.x(), q.y(), q.z()})
               << ",\n        \"cam_from_rig_translation\": "
               << JsonList({t.x(), t.y(), t.z()}) << ",\n";
      }
      config << "        \"camera_model_name\": \""
             << lens.camera.ModelName() << "\",\n"
             << "        \"camera_params\": " << JsonList(lens.camera.params)
             << "\n      }";
    }
    config << "\n    ]\n  }";
  }
  config << "\n]\n";
  return config.str();
}

}  // namespace colmap
