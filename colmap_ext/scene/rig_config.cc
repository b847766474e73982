#include "colmap_ext/scene/rig_config.h"

#include "calibration/camera_presets.h"

#include "colmap/sensor/models.h"
#include "colmap/util/logging.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

namespace colmap {
namespace {

// The numbers of a JSON list; anything else (a nested list, text, a value
// that is not finite) is an error.
std::vector<double> ReadNumbers(const boost::property_tree::ptree& node) {
  std::vector<double> values;
  for (const auto& child : node) {
    const auto value = child.second.get_value_optional<double>();
    THROW_CHECK(value && std::isfinite(*value) && child.second.empty())
        << "expected a list of finite numbers";
    values.push_back(*value);
  }
  return values;
}

RigConfig::RigCamera ReadLens(const boost::property_tree::ptree& node,
                              bool* has_ref_sensor) {
  RigConfig::RigCamera lens;
  lens.image_prefix = node.get<std::string>("image_prefix");
  lens.image_suffix = node.get<std::string>("image_suffix", "");
  const std::string where =
      "camera with image_prefix \"" + lens.image_prefix + "\": ";

  const auto rotation_node = node.get_child_optional("cam_from_rig_rotation");
  const auto translation_node =
      node.get_child_optional("cam_from_rig_translation");
  THROW_CHECK_EQ(rotation_node.has_value(), translation_node.has_value())
      << where << "give cam_from_rig_rotation and _translation, or neither";
  if (rotation_node && translation_node) {
    const std::vector<double> wxyz = ReadNumbers(rotation_node.get());
    const std::vector<double> xyz = ReadNumbers(translation_node.get());
    THROW_CHECK(wxyz.size() == 4 && xyz.size() == 3)
        << where << "cam_from_rig_rotation needs 4 numbers (w, x, y, z), "
        << "cam_from_rig_translation 3";
    Rigid3d cam_from_rig;
    cam_from_rig.rotation() =
        Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
    THROW_CHECK_GT(cam_from_rig.rotation().norm(), 1e-9)
        << where << "cam_from_rig_rotation is zero";
    cam_from_rig.rotation().normalize();
    cam_from_rig.translation() = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    lens.cam_from_rig = cam_from_rig;
  }

  const auto ref_sensor_node = node.get_child_optional("ref_sensor");
  if (ref_sensor_node && ref_sensor_node.get().get_value<bool>()) {
    THROW_CHECK(!rotation_node && !translation_node)
        << "Reference sensor must not have cam_from_rig";
    THROW_CHECK(!*has_ref_sensor) << "Rig must only have one reference sensor";
    lens.ref_sensor = true;
    *has_ref_sensor = true;
  }

  const auto model_name_node = node.get_child_optional("camera_model_name");
  const auto params_node = node.get_child_optional("camera_params");
  const auto field_node = node.get_child_optional("field_of_view_deg");
  const auto circle_node = node.get_child_optional("image_circle");
  THROW_CHECK_EQ(field_node.has_value(), circle_node.has_value())
      << where << "give field_of_view_deg and image_circle, or neither";
  THROW_CHECK(!(params_node && field_node))
      << where << "give camera_params or field_of_view_deg and image_circle, "
      << "not both";
  THROW_CHECK_EQ(model_name_node.has_value(),
                 params_node.has_value() || field_node.has_value())
      << where << "give camera_model_name with camera_params (or with "
      << "field_of_view_deg and image_circle), or none of them";
  if (!model_name_node) return lens;
  const std::string model_name = node.get<std::string>("camera_model_name");
  THROW_CHECK(ExistsCameraModelWithName(model_name))
      << where << "unknown camera model " << model_name;
  lens.camera = std::make_optional<Camera>();
  lens.camera->model_id = CameraModelNameToId(model_name);
  lens.camera->has_prior_focal_length = true;
  if (params_node) {
    lens.camera->params = ReadNumbers(params_node.get());
    THROW_CHECK_EQ(lens.camera->params.size(),
                   CameraModelNumParams(lens.camera->model_id))
        << where << "number of camera_params of " << model_name;
    return lens;
  }
  // A lens known from its specification: the model fitted to the
  // equidistant lens whose field of view fills the image circle.
  const auto field = field_node->get_value_optional<double>();
  THROW_CHECK(field && field_node->empty())
      << where << "field_of_view_deg must be a number";
  const std::vector<double> circle = ReadNumbers(circle_node.get());
  THROW_CHECK_EQ(circle.size(), 3)
      << where << "image_circle needs 3 numbers (cx, cy, radius in pixels)";
  sphera::PresetCamera start;
  try {
    start = sphera::EquidistantLensCamera(
        model_name, {circle[0], circle[1], circle[2]}, *field);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(where + error.what());
  }
  lens.camera->params = start.params;
  LOG(INFO) << where << model_name << " started from the equidistant "
            << *field << "° lens of its image circle (" << circle[0] << ", "
            << circle[1] << ", " << circle[2] << "), fit within "
            << start.fit_max_error_px << " px: " << lens.camera->ParamsToString();
  return lens;
}

std::vector<RigConfig> ReadRigConfigFile(const std::filesystem::path& path) {
  boost::property_tree::ptree pt;
  boost::property_tree::read_json(path.string().c_str(), pt);
  std::vector<RigConfig> configs;
  for (const auto& rig_node : pt) {
    RigConfig& config = configs.emplace_back();
    bool has_ref_sensor = false;
    for (const auto& lens_node : rig_node.second.get_child("cameras")) {
      config.cameras.push_back(ReadLens(lens_node.second, &has_ref_sensor));
    }
    THROW_CHECK(has_ref_sensor) << "Rig must have one reference sensor";
  }
  return configs;
}

}  // namespace

std::vector<RigConfig> ReadCheckedRigConfig(
    const std::filesystem::path& path) {
  try {
    return ReadRigConfigFile(path);
  } catch (const std::exception& error) {
    throw std::invalid_argument("rig config " + path.string() + ": " +
                                error.what());
  }
}

void ConfigureRigs(const std::filesystem::path& rig_config_path,
                   const std::filesystem::path& database_path,
                   Reconstruction* reconstruction,
                   const bool allow_incomplete_frames) {
  const std::vector<RigConfig> configs = ReadRigConfig(rig_config_path);
  auto database = Database::Open(database_path);
  DatabaseTransaction transaction(database.get());
  ApplyRigConfig(configs, *database, reconstruction, allow_incomplete_frames);
}

std::optional<std::string> RigFrameName(const std::string& image_name,
                                        const RigConfig::RigCamera& lens) {
  const std::string& prefix = lens.image_prefix;
  const std::string& suffix = lens.image_suffix;
  const size_t affix_size = prefix.size() + suffix.size();
  if (affix_size == 0 || image_name.size() <= affix_size ||
      image_name.compare(0, prefix.size(), prefix) != 0 ||
      image_name.compare(
          image_name.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return std::nullopt;
  }
  return image_name.substr(prefix.size(), image_name.size() - affix_size);
}

void CheckOneCameraPerLens(const Database& database,
                           const camera_t lens_camera_id,
                           const Image& image,
                           const std::string& image_prefix) {
  if (image.CameraId() == lens_camera_id) {
    return;
  }
  const Camera first = database.ReadCamera(lens_camera_id);
  const Camera other = database.ReadCamera(image.CameraId());
  std::ostringstream message;
  message << "Image " << image.Name() << " has camera " << image.CameraId()
          << " (" << other.width << " x " << other.height
          << "), the other images with prefix \"" << image_prefix
          << "\" have camera " << lens_camera_id << " (" << first.width
          << " x " << first.height
          << "): one camera per lens is needed. Set "
             "--ImageReader.single_camera_per_folder during feature "
             "extraction, or check that every image of this lens has the "
             "same size.";
  throw std::invalid_argument(message.str());
}

RigFrameLenses::RigFrameLenses(const RigConfig& config) : config_(config) {}

std::optional<std::string> RigFrameLenses::Add(const size_t lens_idx,
                                               const Image& image) {
  std::optional<std::string> frame_name =
      RigFrameName(image.Name(), config_.cameras.at(lens_idx));
  if (!frame_name) {
    return std::nullopt;
  }
  std::vector<const Image*>& lenses = frame_lenses_[*frame_name];
  lenses.resize(config_.cameras.size(), nullptr);
  if (lenses[lens_idx] != nullptr) {
    throw std::invalid_argument(
        "Frame \"" + *frame_name + "\": images " + lenses[lens_idx]->Name() +
        " and " + image.Name() +
        " are both its image of the camera with prefix \"" +
        config_.cameras[lens_idx].image_prefix + "\"");
  }
  lenses[lens_idx] = &image;
  return frame_name;
}

camera_t RigFrameLenses::ConfigureCamera(
    const size_t lens_idx,
    const std::optional<camera_t>& camera_id,
    std::set<camera_t>* rig_camera_ids,
    Database& database,
    Reconstruction* reconstruction) {
  const RigConfig::RigCamera& lens = config_.cameras.at(lens_idx);
  if (!camera_id.has_value()) {
    throw std::invalid_argument("No image has the prefix \"" +
                                lens.image_prefix + "\" and suffix \"" +
                                lens.image_suffix + "\" of a camera in the rig");
  }
  camera_t id = *camera_id;
  if (!rig_camera_ids->insert(id).second) {
    id = MoveToOwnCamera(lens_idx, id, database, reconstruction);
    rig_camera_ids->insert(id);
  }
  if (lens.camera.has_value()) {
    const auto copy_intrinsics = [&lens](Camera& camera) {
      camera.model_id = lens.camera->model_id;
      camera.params = lens.camera->params;
      camera.has_prior_focal_length = lens.camera->has_prior_focal_length;
    };
    Camera database_camera = database.ReadCamera(id);
    copy_intrinsics(database_camera);
    database.UpdateCamera(database_camera);
    if (reconstruction != nullptr) {
      copy_intrinsics(reconstruction->Camera(id));
    }
  }
  return id;
}

camera_t RigFrameLenses::MoveToOwnCamera(const size_t lens_idx,
                                         const camera_t shared_camera_id,
                                         Database& database,
                                         const Reconstruction* reconstruction) {
  const RigConfig::RigCamera& lens = config_.cameras.at(lens_idx);
  if (reconstruction != nullptr) {
    throw std::invalid_argument(
        "the lenses with prefix \"" + lens.image_prefix + "\" and suffix \"" +
        lens.image_suffix + "\" share camera " +
        std::to_string(shared_camera_id) +
        " with another lens of the rig; with --input_path each lens needs "
        "its own camera");
  }
  const camera_t camera_id =
      database.WriteCamera(database.ReadCamera(shared_camera_id));
  for (const auto& [frame_name, lenses] : frame_lenses_) {
    if (lenses[lens_idx] != nullptr) {
      Image moved = *lenses[lens_idx];
      moved.SetCameraId(camera_id);
      database.UpdateImage(moved);
      moved_images_.emplace(moved.ImageId(), camera_id);
    }
  }
  return camera_id;
}

void RigFrameLenses::CheckComplete() const {
  for (const auto& [frame_name, lenses] : frame_lenses_) {
    for (size_t lens_idx = 0; lens_idx < lenses.size(); ++lens_idx) {
      if (lenses[lens_idx] == nullptr) {
        const RigConfig::RigCamera& lens = config_.cameras[lens_idx];
        throw std::invalid_argument(
            "Frame \"" + frame_name + "\" has no image of the camera " +
            "with prefix \"" + lens.image_prefix + "\" (expected " +
            lens.image_prefix + frame_name + lens.image_suffix +
            "); add it, remove the frame's other images, or pass "
            "--allow_incomplete_frames 1");
      }
    }
  }
}

data_t RigFrameLenses::DataId(const Image& image) const {
  data_t data_id = image.DataId();
  if (const auto moved = moved_images_.find(image.ImageId());
      moved != moved_images_.end()) {
    data_id.sensor_id.id = moved->second;
  }
  return data_id;
}

}  // namespace colmap
