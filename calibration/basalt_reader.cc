// Basalt's calibration JSON (cereal; basalt_calibrate writes calibration.json):
//   {"value0": {
//     "T_imu_cam": [{"px", "py", "pz", "qx", "qy", "qz", "qw"}, ...],
//     "intrinsics": [{"camera_type": "kb4" | "ds" | "eucm" | "ucm" |
//                                    "pinhole" | "fov",
//                     "intrinsics": {"fx", "fy", "cx", "cy", ...}}, ...],
//     "resolution": [[width, height], ...], ...}}
// T_imu_cam maps points of the camera's frame into the IMU's, so
//   cam_i_from_cam0 = T_imu_cam_i^-1 T_imu_cam_0.
// Camera types and their extra parameters: kb4 k1..k4 (OPENCV_FISHEYE), ds
// xi, alpha (DOUBLE_SPHERE), eucm alpha, beta (EUCM), ucm alpha (UNIFIED_OMNI
// with xi = alpha / (1 - alpha) and focal lengths f / (1 - alpha), exactly),
// pinhole (PINHOLE), fov w (fitted). Translations in metres; pixels count
// from the centre of the first pixel.
#include <nlohmann/json.hpp>

#include "calibration/calibration_readers.h"

namespace sphera {
namespace calibration_internal {
namespace {

using Json = nlohmann::json;

double Number(const std::string& file, const std::string& field,
              const Json& object, const char* key) {
  if (!object.is_object() || !object.contains(key)) {
    throw CalibrationError(file, field + "." + key, "missing");
  }
  const Json& value = object.at(key);
  if (!value.is_number()) {
    throw CalibrationError(file, field + "." + key, "is not a number");
  }
  return FiniteNumber(file, field + "." + key, value.get<double>());
}

const Json& Array(const std::string& file, const Json& root,
                  const char* key) {
  if (!root.contains(key)) throw CalibrationError(file, key, "missing");
  const Json& value = root.at(key);
  if (!value.is_array()) throw CalibrationError(file, key, "is not a list");
  return value;
}

ParsedCamera ReadCamera(const std::string& file, int index, const Json& entry,
                        const Json& resolution) {
  const std::string name = "cam" + std::to_string(index);
  const std::string field = "intrinsics[" + std::to_string(index) + "]";
  const std::string resolution_field =
      "resolution[" + std::to_string(index) + "]";
  if (!resolution.is_array() || resolution.size() != 2 ||
      !resolution[0].is_number() || !resolution[1].is_number()) {
    throw CalibrationError(file, resolution_field, "must be [width, height]");
  }
  const int width =
      ImageSide(file, resolution_field + "[0]", resolution[0].get<double>());
  const int height =
      ImageSide(file, resolution_field + "[1]", resolution[1].get<double>());

  if (!entry.is_object() || !entry.contains("camera_type") ||
      !entry.at("camera_type").is_string()) {
    throw CalibrationError(file, field + ".camera_type", "missing");
  }
  const std::string type = entry.at("camera_type").get<std::string>();
  if (!entry.contains("intrinsics")) {
    throw CalibrationError(file, field + ".intrinsics", "missing");
  }
  const Json& values = entry.at("intrinsics");
  const std::string values_field = field + ".intrinsics";
  const auto number = [&](const char* key) {
    return Number(file, values_field, values, key);
  };
  GenericLens lens;
  lens.fx = number("fx");
  lens.fy = number("fy");
  lens.cx = number("cx") + 0.5;
  lens.cy = number("cy") + 0.5;
  if (type == "pinhole") {
  } else if (type == "kb4") {
    lens.distortion = LensDistortion::kEquidistant;
    lens.distortion_coeffs = {number("k1"), number("k2"), number("k3"),
                              number("k4")};
  } else if (type == "ds") {
    lens.projection = LensProjection::kDoubleSphere;
    lens.projection_params = {number("xi"), number("alpha")};
  } else if (type == "eucm") {
    lens.projection = LensProjection::kEUCM;
    lens.projection_params = {number("alpha"), number("beta")};
  } else if (type == "ucm") {
    const double alpha = number("alpha");
    if (!(alpha >= 0 && alpha < 1)) {
      throw CalibrationError(file, values_field + ".alpha",
                             FormatDouble(alpha) + " is not in [0, 1)");
    }
    lens.projection = LensProjection::kUnified;
    lens.projection_params = {alpha / (1 - alpha)};
    lens.fx /= 1 - alpha;
    lens.fy /= 1 - alpha;
  } else if (type == "fov") {
    const double w = number("w");
    if (!(w > 0 && w < 3.2)) {
      throw CalibrationError(file, values_field + ".w",
                             FormatDouble(w) + " is not in (0, 3.2)");
    }
    lens.distortion = LensDistortion::kFov;
    lens.distortion_coeffs = {w};
  } else {
    throw CalibrationError(file, field + ".camera_type",
                           "unknown camera type \"" + type +
                               "\" (kb4, ds, eucm, ucm, pinhole, fov)");
  }
  CheckPinhole(file, values_field, lens.fx, lens.fy, lens.cx, lens.cy, width,
               height);
  return LensCamera(name, "Basalt " + type, width, height, lens);
}

}  // namespace

ParsedFile ReadBasalt(const std::string& text, const std::string& file) {
  Json document;
  try {
    document = Json::parse(text);
  } catch (const Json::exception& error) {
    throw CalibrationError(file, "JSON", error.what());
  }
  const Json& root =
      document.is_object() && document.contains("value0") ? document["value0"]
                                                          : document;
  if (!root.is_object()) {
    throw CalibrationError(file, "value0", "is not an object");
  }
  const Json& intrinsics = Array(file, root, "intrinsics");
  const Json& resolutions = Array(file, root, "resolution");
  const Json& poses = Array(file, root, "T_imu_cam");
  const size_t count = intrinsics.size();
  if (resolutions.size() != count || poses.size() != count) {
    const size_t missing =
        std::min({count, resolutions.size(), poses.size()});
    throw CalibrationError(
        file,
        resolutions.size() == missing
            ? "resolution"
            : (poses.size() == missing ? "T_imu_cam" : "intrinsics"),
        "has " + std::to_string(missing) + " entries, the other lists " +
            std::to_string(std::max({count, resolutions.size(), poses.size()})) +
            ": cam" + std::to_string(missing) + " is missing");
  }
  ParsedFile parsed;
  Eigen::Quaterniond imu_from_cam0_rotation;
  Eigen::Vector3d imu_from_cam0_translation;
  for (size_t i = 0; i < count; ++i) {
    ParsedCamera camera =
        ReadCamera(file, static_cast<int>(i), intrinsics[i], resolutions[i]);
    const std::string field = "T_imu_cam[" + std::to_string(i) + "]";
    const Json& pose = poses[i];
    const auto number = [&](const char* key) {
      return Number(file, field, pose, key);
    };
    Eigen::Quaterniond rotation(number("qw"), number("qx"), number("qy"),
                                number("qz"));
    if (std::abs(rotation.norm() - 1) > 1e-3) {
      throw CalibrationError(file, field,
                             "quaternion of norm " +
                                 FormatDouble(rotation.norm()) +
                                 " is not a rotation");
    }
    rotation.normalize();
    const Eigen::Vector3d translation(number("px"), number("py"),
                                      number("pz"));
    CheckTranslation(file, field, translation);
    if (i == 0) {
      imu_from_cam0_rotation = rotation;
      imu_from_cam0_translation = translation;
    }
    // cam_i_from_cam0 = imu_from_cam_i^-1 imu_from_cam0.
    const Eigen::Quaterniond cam_from_imu = rotation.conjugate();
    camera.cam_from_rig_rotation =
        (cam_from_imu * imu_from_cam0_rotation).normalized();
    camera.cam_from_rig_translation =
        cam_from_imu * (imu_from_cam0_translation - translation);
    parsed.cameras.push_back(std::move(camera));
  }
  if (parsed.cameras.size() == 1) {
    parsed.cameras[0].cam_from_rig_rotation.reset();
  }
  return parsed;
}

}  // namespace calibration_internal
}  // namespace sphera
