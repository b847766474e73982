#include "colmap_ext/controllers/rig_direction_check.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include <Eigen/Geometry>

#include "camera_models/registry.h"
#include "colmap/util/types.h"
#include "estimators/rotation_from_rays.h"

namespace colmap {
namespace {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180;
constexpr double kDegPerRad = 180 / 3.14159265358979323846;

// The unit ray of a keypoint: SPHERA's models lift rays beyond 180°;
// COLMAP's other models through the camera.
std::optional<Eigen::Vector3d> RayInCam(const Camera& camera,
                                        const Eigen::Vector2d& pixel) {
  static const std::set<int> kSpheraModelIds = {1, 4, 5, 10, 16, 17,
                                                64, 65, 66};
  const int model_id = static_cast<int>(camera.model_id);
  if (kSpheraModelIds.count(model_id) > 0) {
    Eigen::Vector3d ray_in_cam;
    if (!sphera::RayFromImage(model_id, camera.params, pixel, &ray_in_cam) ||
        !ray_in_cam.allFinite() || ray_in_cam.norm() == 0) {
      return std::nullopt;
    }
    return ray_in_cam.normalized();
  }
  const std::optional<Eigen::Vector2d> point_in_cam = camera.CamFromImg(pixel);
  if (!point_in_cam || !point_in_cam->allFinite()) {
    return std::nullopt;
  }
  return point_in_cam->homogeneous().normalized();
}

// What all names share: the folder of their common prefix, else "*" and
// their common suffix (lenses told apart by suffix, NAME_1.JPG ...).
std::string CommonPattern(const std::vector<std::string>& names) {
  if (names.empty()) return "";
  if (names.size() == 1) return names[0];
  std::string prefix = names[0], suffix = names[0];
  for (const std::string& name : names) {
    size_t n = 0;
    while (n < prefix.size() && n < name.size() && prefix[n] == name[n]) ++n;
    prefix.resize(n);
    n = 0;
    while (n < suffix.size() && n < name.size() &&
           suffix[suffix.size() - 1 - n] == name[name.size() - 1 - n]) {
      ++n;
    }
    suffix = suffix.substr(suffix.size() - n);
  }
  const size_t slash = prefix.rfind('/');
  if (slash != std::string::npos) return prefix.substr(0, slash + 1);
  return suffix.empty() ? "" : "*" + suffix;
}

std::string Format(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

std::string DirectionText(const Eigen::Matrix3d& cam_from_rig) {
  const Eigen::Vector3d axis = cam_from_rig.row(2);
  Eigen::Quaterniond q(cam_from_rig);
  if (q.w() < 0) q.coeffs() *= -1;  // the same rotation, w >= 0 as written
  char text[160];
  std::snprintf(text, sizeof(text),
                "optical axis (%.3f, %.3f, %.3f) in the rig, "
                "cam_from_rig_rotation [%.4f, %.4f, %.4f, %.4f]",
                axis.x(), axis.y(), axis.z(), q.w(), q.x(), q.y(), q.z());
  return text;
}

}  // namespace

std::string RigCheckOptions::Check() const {
  if (!(max_angle_deg > 0 && max_angle_deg <= 180)) {
    return "--max_angle_deg must be in (0, 180], got " +
           Format("%g", max_angle_deg);
  }
  if (!(max_ray_error_deg > 0 && max_ray_error_deg < 90)) {
    return "--max_ray_error_deg must be in (0, 90), got " +
           Format("%g", max_ray_error_deg);
  }
  if (min_num_inliers < 3 || min_num_inliers > 100000) {
    return "--min_num_inliers must be in [3, 100000], got " +
           std::to_string(min_num_inliers);
  }
  return "";
}

RigCheckReport CheckRigDirectionsInDatabase(const Database& database,
                                            const RigCheckOptions& options) {
  if (const std::string error = options.Check(); !error.empty()) {
    throw std::invalid_argument(error);
  }
  RigCheckReport report;

  // The lenses of every rig of more than one camera, indexed per rig.
  std::map<rig_t, std::vector<LensCheck>> rig_lenses;
  std::unordered_map<camera_t, std::pair<rig_t, int>> lens_of_camera;
  for (const Rig& rig : database.ReadAllRigs()) {
    if (rig.NumSensors() < 2) continue;
    std::vector<LensCheck>& lenses = rig_lenses[rig.RigId()];
    auto add = [&](const sensor_t& sensor_id, bool reference) {
      if (sensor_id.type != SensorType::CAMERA) return;
      LensCheck lens;
      lens.rig_id = rig.RigId();
      lens.camera_id = sensor_id.id;
      lens.reference = reference;
      if (reference) {
        lens.configured = true;
      } else if (const std::optional<Rigid3d>& sensor_from_rig =
                     rig.MaybeSensorFromRig(sensor_id)) {
        lens.configured = true;
        lens.config_cam_from_rig =
            sensor_from_rig->rotation().toRotationMatrix();
      }
      lens_of_camera[lens.camera_id] = {rig.RigId(),
                                        static_cast<int>(lenses.size())};
      lenses.push_back(lens);
    };
    add(rig.RefSensorId(), true);
    for (const auto& [sensor_id, sensor_from_rig] : rig.NonRefSensors()) {
      add(sensor_id, false);
    }
    if (lenses.size() < 2) {
      rig_lenses.erase(rig.RigId());
    }
  }
  if (rig_lenses.empty()) {
    throw std::invalid_argument(
        "the database has no rig of more than one camera: run "
        "rig_configurator with the rig config first");
  }
  report.num_rigs = static_cast<int>(rig_lenses.size());

  std::unordered_map<image_t, frame_t> frame_of_image;
  for (const Frame& frame : database.ReadAllFrames()) {
    if (rig_lenses.count(frame.RigId()) == 0) continue;
    ++report.num_frames;
    for (const data_t& data_id : frame.ImageIds()) {
      frame_of_image[static_cast<image_t>(data_id.id)] = frame.FrameId();
    }
  }
  if (report.num_frames == 0) {
    throw std::invalid_argument(
        "the database has no frame of a rig of more than one camera: run "
        "rig_configurator with the rig config first");
  }

  std::unordered_map<camera_t, std::vector<std::string>> names_of_camera;
  std::unordered_map<image_t, camera_t> camera_of_image;
  for (const Image& image : database.ReadAllImages()) {
    names_of_camera[image.CameraId()].push_back(image.Name());
    camera_of_image[image.ImageId()] = image.CameraId();
  }
  std::unordered_map<camera_t, Camera> cameras;
  for (const Camera& camera : database.ReadAllCameras()) {
    cameras.emplace(camera.camera_id, camera);
  }

  std::map<rig_t, std::vector<sphera::LensPairRotation>> measurements;
  std::map<std::pair<rig_t, int>, std::set<frame_t>> frames_of_lens;
  sphera::RotationFromRaysOptions ray_options;
  ray_options.max_error_rad = options.max_ray_error_deg * kRadPerDeg;
  ray_options.min_num_inliers = options.min_num_inliers;
  std::unordered_map<image_t, FeatureKeypoints> keypoints;
  auto keypoints_of = [&](image_t image_id) -> const FeatureKeypoints& {
    auto it = keypoints.find(image_id);
    if (it == keypoints.end()) {
      it = keypoints.emplace(image_id, database.ReadKeypoints(image_id)).first;
    }
    return it->second;
  };
  for (const auto& [pair_id, geometry] : database.ReadTwoViewGeometries()) {
    const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
    const auto frame1 = frame_of_image.find(image_id1);
    const auto frame2 = frame_of_image.find(image_id2);
    if (geometry.inlier_matches.empty() || frame1 == frame_of_image.end() ||
        frame2 == frame_of_image.end() || frame1->second != frame2->second) {
      continue;
    }
    const camera_t camera_id1 = camera_of_image.at(image_id1);
    const camera_t camera_id2 = camera_of_image.at(image_id2);
    const auto lens1 = lens_of_camera.find(camera_id1);
    const auto lens2 = lens_of_camera.find(camera_id2);
    if (lens1 == lens_of_camera.end() || lens2 == lens_of_camera.end() ||
        lens1->second.first != lens2->second.first ||
        lens1->second.second == lens2->second.second) {
      continue;
    }
    ++report.num_frame_pairs;
    const Camera& camera1 = cameras.at(camera_id1);
    const Camera& camera2 = cameras.at(camera_id2);
    const FeatureKeypoints& keypoints1 = keypoints_of(image_id1);
    const FeatureKeypoints& keypoints2 = keypoints_of(image_id2);
    std::vector<Eigen::Vector3d> rays_in_cam1, rays_in_cam2;
    for (const FeatureMatch& match : geometry.inlier_matches) {
      const FeatureKeypoint& keypoint1 = keypoints1.at(match.point2D_idx1);
      const FeatureKeypoint& keypoint2 = keypoints2.at(match.point2D_idx2);
      const std::optional<Eigen::Vector3d> ray1 = RayInCam(
          camera1, Eigen::Vector2d(keypoint1.x, keypoint1.y));
      const std::optional<Eigen::Vector3d> ray2 = RayInCam(
          camera2, Eigen::Vector2d(keypoint2.x, keypoint2.y));
      if (ray1 && ray2) {
        rays_in_cam1.push_back(*ray1);
        rays_in_cam2.push_back(*ray2);
      }
    }
    const sphera::RotationFromRays rotation =
        sphera::EstimateRotationFromRays(rays_in_cam1, rays_in_cam2,
                                         ray_options);
    if (!rotation.success) continue;
    ++report.num_measured_pairs;
    sphera::LensPairRotation measurement;
    measurement.lens1 = lens1->second.second;
    measurement.lens2 = lens2->second.second;
    measurement.cam2_from_cam1 = rotation.cam2_from_cam1;
    measurement.num_inliers = rotation.num_inliers;
    measurements[lens1->second.first].push_back(measurement);
    frames_of_lens[lens1->second].insert(frame1->second);
    frames_of_lens[lens2->second].insert(frame1->second);
  }

  sphera::RigDirectionCheckOptions check_options;
  check_options.max_disagreement_rad = options.max_angle_deg * kRadPerDeg;
  for (auto& [rig_id, lenses] : rig_lenses) {
    // Lenses without a configured direction take no part in the check.
    std::vector<Eigen::Matrix3d> config_cam_from_rig;
    std::vector<int> index_in_check(lenses.size(), -1);
    for (size_t i = 0; i < lenses.size(); ++i) {
      if (lenses[i].configured) {
        index_in_check[i] = static_cast<int>(config_cam_from_rig.size());
        config_cam_from_rig.push_back(lenses[i].config_cam_from_rig);
      }
    }
    std::vector<sphera::LensPairRotation> configured_measurements;
    for (sphera::LensPairRotation measurement : measurements[rig_id]) {
      measurement.lens1 = index_in_check[measurement.lens1];
      measurement.lens2 = index_in_check[measurement.lens2];
      if (measurement.lens1 >= 0 && measurement.lens2 >= 0) {
        configured_measurements.push_back(measurement);
      }
    }
    const std::vector<sphera::LensDirection> directions =
        sphera::CheckRigDirections(config_cam_from_rig,
                                   configured_measurements, check_options);
    for (size_t i = 0; i < lenses.size(); ++i) {
      LensCheck& lens = lenses[i];
      lens.image_pattern = CommonPattern(names_of_camera[lens.camera_id]);
      lens.num_frames = static_cast<int>(
          frames_of_lens[{rig_id, static_cast<int>(i)}].size());
      if (index_in_check[i] >= 0) {
        lens.direction = directions[index_in_check[i]];
      }
      report.lenses.push_back(lens);
    }
  }
  return report;
}

RigCheckReport CheckRigDirectionsInDatabaseFile(
    const std::filesystem::path& path, const RigCheckOptions& options) {
  if (const std::string error = options.Check(); !error.empty()) {
    throw std::invalid_argument(error);
  }
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error) ||
      std::filesystem::file_size(path, error) == 0) {
    throw std::invalid_argument("--database_path " + path.string() +
                                ": no such database (run feature_extractor, "
                                "rig_configurator and a matcher first)");
  }
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() /
      ("sphera_rig_check_" + std::to_string(std::random_device()()));
  std::filesystem::create_directories(folder);
  struct RemoveFolder {
    std::filesystem::path folder;
    ~RemoveFolder() {
      std::error_code ignored;
      std::filesystem::remove_all(folder, ignored);
    }
  } remove_folder{folder};
  const std::filesystem::path copy = folder / "database.db";
  std::filesystem::copy_file(path, copy);
  // The copy's tables are read before the copy is deleted.
  return CheckRigDirectionsInDatabase(*Database::Open(copy), options);
}

std::string LensCheckName(const LensCheck& lens) {
  return "rig " + std::to_string(lens.rig_id) + " camera " +
         std::to_string(lens.camera_id) +
         (lens.image_pattern.empty() ? "" : " (" + lens.image_pattern + ")");
}

std::string RigCheckText(const RigCheckReport& report) {
  std::ostringstream text;
  text << report.num_rigs << " rig(s), " << report.num_frames
       << " frame(s), " << report.num_frame_pairs
       << " verified image pair(s) inside frames, "
       << report.num_measured_pairs << " with a lens rotation\n";
  for (const LensCheck& lens : report.lenses) {
    const sphera::LensDirection& direction = lens.direction;
    text << "  " << LensCheckName(lens) << (lens.reference ? " ref" : "")
         << ": ";
    if (!lens.configured) {
      text << "unchecked (no direction in the rig config)\n";
      continue;
    }
    if (direction.status == sphera::LensDirectionStatus::kUnchecked) {
      text << "unchecked (no lens pair measured)\n";
      continue;
    }
    text << (direction.measured
                 ? Format("%.2f", direction.angle_off_rad * kDegPerRad) +
                       " deg off"
                 : std::string("direction not measured"))
         << ", " << direction.num_pairs << " lens pair(s), "
         << lens.num_frames << " frame(s), " << direction.num_inliers
         << " inlier rays";
    // The measured axis in the measured reference lens's frame.
    const LensCheck* reference = nullptr;
    for (const LensCheck& other : report.lenses) {
      if (other.rig_id == lens.rig_id && other.reference) reference = &other;
    }
    if (!lens.reference && direction.measured && reference != nullptr &&
        reference->direction.measured) {
      const Eigen::Vector2d axis = sphera::LensAxisAzimuthElevationDeg(
          direction.measured_cam_from_rig *
          reference->direction.measured_cam_from_rig.transpose());
      text << "; measured axis at azimuth " << Format("%.2f", axis.x())
           << " deg, elevation " << Format("%.2f", axis.y()) << " deg";
    }
    text
         << (direction.status == sphera::LensDirectionStatus::kContradicted
                 ? "  CONTRADICTED"
                 : "")
         << "\n";
  }
  return text.str();
}

std::string LensContradictionText(const LensCheck& lens,
                                  const RigCheckOptions& options) {
  const sphera::LensDirection& direction = lens.direction;
  const double angle_rad = direction.measured
                               ? direction.angle_off_rad
                               : direction.max_pair_disagreement_rad;
  return "the rig config's direction of " + LensCheckName(lens) + " is " +
         Format("%.1f", angle_rad * kDegPerRad) +
         " deg off what its images say (more than --max_angle_deg " +
         Format("%g", options.max_angle_deg) + "; from " +
         std::to_string(direction.num_pairs) + " lens pair(s) in " +
         std::to_string(lens.num_frames) + " frame(s)). Config: " +
         DirectionText(lens.config_cam_from_rig) +
         (direction.measured
              ? "; images: " + DirectionText(direction.measured_cam_from_rig)
              : "; its direction is not measured (no pair with a lens that "
                "agrees)");
}

}  // namespace colmap
