// Kalibr's camchain YAML (kalibr_calibrate_cameras, camchain-*.yaml):
//   cam0:
//     camera_model: pinhole | omni | ds | eucm
//     intrinsics: pinhole [fu, fv, pu, pv]; omni [xi, fu, fv, pu, pv];
//                 ds [xi, alpha, fu, fv, pu, pv]; eucm [alpha, beta, fu, fv,
//                 pu, pv]
//     distortion_model: radtan | equidistant | fov | none
//     distortion_coeffs: radtan [k1, k2, r1, r2]; equidistant [k1..k4];
//                        fov [w]; none []
//     resolution: [width, height]
//     rostopic: /cam0/image_raw
//   cam1:
//     T_cn_cnm1: 4x4, maps points of cam0's frame into cam1's
//     ...
// The camera frame is OpenCV's (x right, y down, z forward); translations in
// metres; pixels count from the centre of the first pixel.
#include <algorithm>
#include <map>
#include <regex>

#include <yaml-cpp/yaml.h>

#include "calibration/calibration_readers.h"

namespace sphera {
namespace calibration_internal {
namespace {

std::vector<double> Numbers(const std::string& file, const std::string& field,
                            const YAML::Node& node, size_t count) {
  if (!node.IsDefined() || node.IsNull()) {
    throw CalibrationError(file, field, "missing");
  }
  if (!node.IsSequence() || node.size() != count) {
    throw CalibrationError(
        file, field,
        "must be a list of " + std::to_string(count) + " numbers");
  }
  std::vector<double> values;
  for (size_t i = 0; i < count; ++i) {
    const std::string item = field + "[" + std::to_string(i) + "]";
    double value;
    if (!node[i].IsScalar() || !YAML::convert<double>::decode(node[i], value)) {
      throw CalibrationError(file, item, "is not a number");
    }
    values.push_back(FiniteNumber(file, item, value));
  }
  return values;
}

std::string Text(const std::string& file, const std::string& field,
                 const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) {
    throw CalibrationError(file, field, "missing");
  }
  if (!node.IsScalar()) throw CalibrationError(file, field, "is not a name");
  return node.Scalar();
}

struct KalibrProjection {
  const char* name;
  LensProjection projection;
  int num_projection_params;  // before fu, fv, pu, pv
};

const KalibrProjection kProjections[] = {
    {"pinhole", LensProjection::kPinhole, 0},
    {"omni", LensProjection::kUnified, 1},
    {"ds", LensProjection::kDoubleSphere, 2},
    {"eucm", LensProjection::kEUCM, 2},
};

struct KalibrDistortion {
  const char* name;
  LensDistortion distortion;
  size_t num_coeffs;
};

const KalibrDistortion kDistortions[] = {
    {"none", LensDistortion::kNone, 0},
    {"radtan", LensDistortion::kRadTan, 4},
    {"equidistant", LensDistortion::kEquidistant, 4},
    {"equi", LensDistortion::kEquidistant, 4},
    {"fov", LensDistortion::kFov, 1},
};

ParsedCamera ReadCamera(const std::string& file, const std::string& name,
                        const YAML::Node& node) {
  if (!node.IsMap()) {
    throw CalibrationError(file, name, "is not a map of camera fields");
  }
  const std::string model_field = name + ".camera_model";
  const std::string model_name = Text(file, model_field, node["camera_model"]);
  const auto projection = std::find_if(
      std::begin(kProjections), std::end(kProjections),
      [&](const KalibrProjection& p) { return model_name == p.name; });
  if (projection == std::end(kProjections)) {
    throw CalibrationError(file, model_field,
                           "unknown camera model \"" + model_name +
                               "\" (pinhole, omni, ds, eucm)");
  }
  std::string distortion_name = "none";
  if (node["distortion_model"].IsDefined()) {
    distortion_name =
        Text(file, name + ".distortion_model", node["distortion_model"]);
  }
  const auto distortion = std::find_if(
      std::begin(kDistortions), std::end(kDistortions),
      [&](const KalibrDistortion& d) { return distortion_name == d.name; });
  if (distortion == std::end(kDistortions)) {
    throw CalibrationError(file, name + ".distortion_model",
                           "unknown distortion model \"" + distortion_name +
                               "\" (radtan, equidistant, fov, none)");
  }

  const std::vector<double> resolution =
      Numbers(file, name + ".resolution", node["resolution"], 2);
  const int width = ImageSide(file, name + ".resolution[0]", resolution[0]);
  const int height = ImageSide(file, name + ".resolution[1]", resolution[1]);

  const int num_projection = projection->num_projection_params;
  const std::vector<double> intrinsics =
      Numbers(file, name + ".intrinsics", node["intrinsics"],
              num_projection + 4);
  GenericLens lens;
  lens.projection = projection->projection;
  lens.projection_params.assign(intrinsics.begin(),
                                intrinsics.begin() + num_projection);
  lens.fx = intrinsics[num_projection];
  lens.fy = intrinsics[num_projection + 1];
  lens.cx = intrinsics[num_projection + 2] + 0.5;
  lens.cy = intrinsics[num_projection + 3] + 0.5;
  CheckPinhole(file, name + ".intrinsics", lens.fx, lens.fy, lens.cx, lens.cy,
               width, height);
  lens.distortion = distortion->distortion;
  if (distortion->num_coeffs > 0 || node["distortion_coeffs"].IsDefined()) {
    const YAML::Node coeffs = node["distortion_coeffs"];
    // "none" is written with an empty list or none at all.
    if (distortion->num_coeffs > 0 || (coeffs.IsSequence() && coeffs.size())) {
      lens.distortion_coeffs = Numbers(file, name + ".distortion_coeffs",
                                       coeffs, distortion->num_coeffs);
    }
  }
  return LensCamera(name, "Kalibr " + model_name + "-" + distortion_name,
                    width, height, lens);
}

}  // namespace

ParsedFile ReadKalibr(const std::string& text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& error) {
    throw CalibrationError(file, "YAML", error.what());
  }
  if (!root.IsMap()) {
    throw CalibrationError(file, "camchain",
                           "is not a map of cameras cam0, cam1, ...");
  }
  std::map<int, YAML::Node> cameras;
  const std::regex camera_key("cam([0-9]{1,6})");
  for (const auto& entry : root) {
    if (!entry.first.IsScalar()) continue;
    std::smatch match;
    const std::string key = entry.first.Scalar();
    if (std::regex_match(key, match, camera_key)) {
      if (!cameras.emplace(std::stoi(match[1]), entry.second).second) {
        throw CalibrationError(file, key, "appears twice");
      }
    }
  }
  if (cameras.empty()) {
    throw CalibrationError(file, "cam0", "missing: no camera in the camchain");
  }
  ParsedFile parsed;
  Eigen::Quaterniond cam_from_rig_rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d cam_from_rig_translation = Eigen::Vector3d::Zero();
  int expected = 0;
  for (const auto& [index, node] : cameras) {
    const std::string name = "cam" + std::to_string(expected);
    if (index != expected) {
      throw CalibrationError(file, name,
                             "missing: the chain of T_cn_cnm1 goes from cam" +
                                 std::to_string(expected - 1) + " to cam" +
                                 std::to_string(index) + " through it");
    }
    try {
      ParsedCamera camera = ReadCamera(file, name, node);
      if (index > 0) {
        const std::string field = name + ".T_cn_cnm1";
        const YAML::Node transform = node["T_cn_cnm1"];
        if (!transform.IsDefined() || transform.IsNull()) {
          throw CalibrationError(
              file, field,
              "missing: the pose of " + name + " relative to cam" +
                  std::to_string(index - 1));
        }
        if (!transform.IsSequence() || transform.size() != 4) {
          throw CalibrationError(file, field,
                                 "must be a 4x4 matrix (4 rows of 4 numbers)");
        }
        Eigen::Matrix4d matrix;
        for (int row = 0; row < 4; ++row) {
          const std::vector<double> values =
              Numbers(file, field + "[" + std::to_string(row) + "]",
                      transform[row], 4);
          for (int col = 0; col < 4; ++col) matrix(row, col) = values[col];
        }
        if ((matrix.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() >
            1e-9) {
          throw CalibrationError(file, field, "last row is not 0 0 0 1");
        }
        const Eigen::Quaterniond rotation =
            RotationOfMatrix(file, field, matrix.topLeftCorner<3, 3>());
        const Eigen::Vector3d translation = matrix.topRightCorner<3, 1>();
        CheckTranslation(file, field, translation);
        // cam_n_from_rig = cam_n_from_cam_{n-1} * cam_{n-1}_from_rig.
        cam_from_rig_translation =
            rotation * cam_from_rig_translation + translation;
        cam_from_rig_rotation = (rotation * cam_from_rig_rotation).normalized();
        CheckTranslation(file, field + " (chained to cam0)",
                         cam_from_rig_translation);
      }
      camera.cam_from_rig_rotation = cam_from_rig_rotation;
      camera.cam_from_rig_translation = cam_from_rig_translation;
      parsed.cameras.push_back(std::move(camera));
    } catch (const YAML::Exception& error) {
      throw CalibrationError(file, name, error.what());
    }
    ++expected;
  }
  if (parsed.cameras.size() == 1) {
    parsed.cameras[0].cam_from_rig_rotation.reset();
  }
  return parsed;
}

}  // namespace calibration_internal
}  // namespace sphera
