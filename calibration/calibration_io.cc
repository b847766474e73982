#include "calibration/calibration_io.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include <Eigen/SVD>

#include "calibration/calibration_readers.h"
#include "camera_models/registry.h"

namespace sphera {

namespace calibration_internal {

double FiniteNumber(const std::string& file, const std::string& field,
                    double value) {
  if (!std::isfinite(value)) {
    throw CalibrationError(file, field,
                           FormatDouble(value) + " is not a finite number");
  }
  return value;
}

int ImageSide(const std::string& file, const std::string& field,
              double value) {
  FiniteNumber(file, field, value);
  if (value != std::floor(value) || value < 1 || value > kMaxImageSide) {
    throw CalibrationError(file, field,
                           FormatDouble(value) +
                               " is not an image size in whole pixels in "
                               "[1, " +
                               std::to_string(kMaxImageSide) + "]");
  }
  return static_cast<int>(value);
}

void CheckPinhole(const std::string& file, const std::string& field,
                  double fx, double fy, double cx, double cy, int width,
                  int height) {
  const double max_focal = kMaxFocalPerSide * std::max(width, height);
  for (const auto& [name, value] : {std::make_pair("fx", fx),
                                    std::make_pair("fy", fy)}) {
    FiniteNumber(file, field + " " + name, value);
    if (!(value > 0) || value > max_focal) {
      throw CalibrationError(file, field + " " + name,
                             "focal length " + FormatDouble(value) +
                                 " is not in (0, " + FormatDouble(max_focal) +
                                 "] pixels for a " + std::to_string(width) +
                                 "x" + std::to_string(height) + " image");
    }
  }
  for (const auto& [name, value, side] :
       {std::make_tuple("cx", cx, width), std::make_tuple("cy", cy, height)}) {
    FiniteNumber(file, field + " " + name, value);
    if (value < -side || value > 2.0 * side) {
      throw CalibrationError(
          file, field + " " + name,
          "principal point " + FormatDouble(value) +
              " is more than an image size outside the image (0 to " +
              std::to_string(side) + ")");
    }
  }
}

namespace {

std::string ModelName(int model_id) {
  return internal::VisitModel(model_id, [](auto model) {
    return std::string(decltype(model)::kModelName);
  });
}

// Our model of the lens when it is one of ours, exactly: (id, params).
std::optional<std::pair<ModelId, std::vector<double>>> ExactModel(
    const GenericLens& lens) {
  if (lens.skew != 0) return std::nullopt;
  std::vector<double> params = {lens.fx, lens.fy, lens.cx, lens.cy};
  const std::vector<double>& k = lens.distortion_coeffs;
  const auto append = [&params](const std::vector<double>& values) {
    params.insert(params.end(), values.begin(), values.end());
    return params;
  };
  const auto padded = [&k](size_t n) {
    std::vector<double> values(k.begin(), k.begin() + std::min(n, k.size()));
    values.resize(n, 0.0);
    return values;
  };
  const bool rational_is_radtan = std::all_of(
      k.begin() + std::min<size_t>(4, k.size()), k.end(),
      [](double v) { return v == 0; });
  switch (lens.projection) {
    case LensProjection::kPinhole:
      if (lens.distortion == LensDistortion::kNone) {
        return std::make_pair(ModelId::kPinhole, params);
      }
      if (lens.distortion == LensDistortion::kRadTan ||
          (lens.distortion == LensDistortion::kRational &&
           rational_is_radtan)) {
        return std::make_pair(ModelId::kOpenCV, append(padded(4)));
      }
      if (lens.distortion == LensDistortion::kEquidistant) {
        return std::make_pair(ModelId::kOpenCVFisheye, append(padded(4)));
      }
      return std::nullopt;
    case LensProjection::kUnified:
      if (lens.distortion == LensDistortion::kNone ||
          lens.distortion == LensDistortion::kRadTan) {
        append({lens.projection_params.at(0)});
        return std::make_pair(ModelId::kUnifiedOmni, append(padded(4)));
      }
      return std::nullopt;
    case LensProjection::kDoubleSphere:
      if (lens.distortion != LensDistortion::kNone) return std::nullopt;
      return std::make_pair(ModelId::kDoubleSphere,
                            append(lens.projection_params));
    case LensProjection::kEUCM:
      if (lens.distortion != LensDistortion::kNone) return std::nullopt;
      return std::make_pair(ModelId::kEUCM, append(lens.projection_params));
  }
  return std::nullopt;
}

}  // namespace

ParsedCamera LensCamera(const std::string& name,
                        const std::string& source_model, int width,
                        int height, const GenericLens& lens) {
  ParsedCamera camera;
  camera.name = name;
  camera.source_model = source_model;
  camera.width = width;
  camera.height = height;
  if (const auto exact = ExactModel(lens)) {
    camera.model_id = static_cast<int>(exact->first);
    camera.params = exact->second;
  } else {
    camera.sample_lens = [lens, width,
                          height](const LensSamplingOptions& sampling) {
      return SampleLensByProjection(
          [&lens](const Eigen::Vector3d& ray, Eigen::Vector2d* pixel) {
            return lens.ImageFromRay(ray, pixel);
          },
          width, height, sampling);
    };
  }
  return camera;
}

Eigen::Quaterniond RotationOfMatrix(const std::string& file,
                                    const std::string& field,
                                    const Eigen::Matrix3d& matrix) {
  if (!matrix.allFinite()) {
    throw CalibrationError(file, field, "the rotation is not finite");
  }
  const double deviation =
      (matrix.transpose() * matrix - Eigen::Matrix3d::Identity())
          .cwiseAbs()
          .maxCoeff();
  if (deviation > 1e-3 || matrix.determinant() < 0) {
    throw CalibrationError(
        file, field,
        "the 3x3 block is not a rotation (R^T R differs from I by " +
            FormatDouble(deviation) + ", det " +
            FormatDouble(matrix.determinant()) + ")");
  }
  // The nearest rotation: files round their entries.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      matrix, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return Eigen::Quaterniond(svd.matrixU() * svd.matrixV().transpose())
      .normalized();
}

void CheckTranslation(const std::string& file, const std::string& field,
                      const Eigen::Vector3d& translation) {
  if (!translation.allFinite() ||
      translation.norm() > kMaxTranslation) {
    throw CalibrationError(file, field,
                           "translation of length " +
                               FormatDouble(translation.norm()) +
                               " is not finite or above " +
                               FormatDouble(kMaxTranslation));
  }
}

}  // namespace calibration_internal

using calibration_internal::ParsedCamera;
using calibration_internal::ParsedFile;

CalibrationError::CalibrationError(const std::string& file,
                                   const std::string& field,
                                   const std::string& problem)
    : std::runtime_error([&] {
        std::string message = file + ": " + field + ": " + problem;
        // One line whatever a parser's message holds.
        std::replace(message.begin(), message.end(), '\n', ' ');
        std::replace(message.begin(), message.end(), '\r', ' ');
        return message;
      }()) {}

CalibrationFormat CalibrationFormatFromName(const std::string& name) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  for (const CalibrationFormat format :
       {CalibrationFormat::kAuto, CalibrationFormat::kKalibr,
        CalibrationFormat::kOpenCV, CalibrationFormat::kOCamCalib,
        CalibrationFormat::kBasalt}) {
    if (lower == CalibrationFormatName(format)) return format;
  }
  throw std::invalid_argument("--format: unknown calibration format \"" +
                              name +
                              "\" (auto, kalibr, opencv, ocamcalib, basalt)");
}

const char* CalibrationFormatName(CalibrationFormat format) {
  switch (format) {
    case CalibrationFormat::kAuto:
      return "auto";
    case CalibrationFormat::kKalibr:
      return "kalibr";
    case CalibrationFormat::kOpenCV:
      return "opencv";
    case CalibrationFormat::kOCamCalib:
      return "ocamcalib";
    case CalibrationFormat::kBasalt:
      return "basalt";
  }
  return "?";
}

CalibrationFormat DetectCalibrationFormat(const std::string& text) {
  const size_t start = text.find_first_not_of(" \t\r\n");
  if (start == std::string::npos) return CalibrationFormat::kAuto;
  const auto contains = [&text](const char* word) {
    return text.find(word) != std::string::npos;
  };
  if (text.compare(start, 5, "<?xml") == 0 || text.compare(start, 5, "%YAML") == 0 ||
      contains("opencv-matrix") || contains("<opencv_storage>")) {
    return CalibrationFormat::kOpenCV;
  }
  if (text[start] == '{' && (contains("\"value0\"") || contains("\"T_imu_cam\""))) {
    return CalibrationFormat::kBasalt;
  }
  if (contains("camera_model") && contains("intrinsics") &&
      contains("cam0")) {
    return CalibrationFormat::kKalibr;
  }
  if (contains("polynomial coefficients") || contains("affine parameters")) {
    return CalibrationFormat::kOCamCalib;
  }
  return CalibrationFormat::kAuto;
}

ImportedCalibration ImportCalibrationText(
    const std::string& text, const std::string& file_name,
    const CalibrationImportOptions& options) {
  int target_id = -1;
  if (!options.camera_model.empty()) {
    target_id = ModelIdFromName(options.camera_model);
    if (target_id < 0 ||
        target_id == static_cast<int>(ModelId::kEquirectangular)) {
      throw std::invalid_argument(
          "--camera_model: " + options.camera_model +
          " is not a lens model of ours (PINHOLE, OPENCV, OPENCV_FISHEYE, "
          "THIN_PRISM_FISHEYE, EUCM, UNIFIED_OMNI, DOUBLE_SPHERE, OCAM)");
    }
  }
  if (!(options.half_field_deg >= 0 && options.half_field_deg <= 180)) {
    std::ostringstream message;
    message << "--half_field_deg: " << options.half_field_deg
            << " is not an angle from the optical axis in [0, 180] degrees "
               "(0: the whole image frame)";
    throw std::invalid_argument(message.str());
  }
  LensSamplingOptions sampling;
  if (options.half_field_deg > 0) {
    sampling.max_angle_deg = options.half_field_deg;
  }
  ImportedCalibration calibration;
  calibration.file = file_name;
  calibration.format = options.format;
  if (calibration.format == CalibrationFormat::kAuto) {
    calibration.format = DetectCalibrationFormat(text);
    if (calibration.format == CalibrationFormat::kAuto) {
      throw CalibrationError(file_name, "format",
                             "not a Kalibr, OpenCV, OCamCalib or Basalt "
                             "calibration; name it with --format");
    }
  }
  ParsedFile parsed;
  switch (calibration.format) {
    case CalibrationFormat::kKalibr:
      parsed = calibration_internal::ReadKalibr(text, file_name);
      break;
    case CalibrationFormat::kOpenCV:
      parsed = calibration_internal::ReadOpenCV(text, file_name);
      break;
    case CalibrationFormat::kOCamCalib:
      parsed = calibration_internal::ReadOCamCalib(text, file_name);
      break;
    case CalibrationFormat::kBasalt:
      parsed = calibration_internal::ReadBasalt(text, file_name);
      break;
    case CalibrationFormat::kAuto:
      break;
  }
  if (parsed.cameras.empty()) {
    throw CalibrationError(file_name, "cameras", "the file has no camera");
  }
  calibration.notes = parsed.notes;

  for (ParsedCamera& parsed_camera : parsed.cameras) {
    ImportedCamera camera;
    camera.name = parsed_camera.name;
    camera.source_model = parsed_camera.source_model;
    camera.width = parsed_camera.width;
    camera.height = parsed_camera.height;
    camera.cam_from_rig_rotation = parsed_camera.cam_from_rig_rotation;
    camera.cam_from_rig_translation = parsed_camera.cam_from_rig_translation;
    const bool exact = parsed_camera.model_id >= 0 &&
                       (target_id < 0 || target_id == parsed_camera.model_id);
    if (parsed_camera.model_id >= 0) {
      // The file's model is ours: its own checks (a fold inside the image,
      // a parameter out of range) before anything is made of it.
      const std::string message =
          CheckParams(parsed_camera.model_id, parsed_camera.params,
                      camera.width, camera.height);
      if (!message.empty()) {
        throw CalibrationError(file_name, camera.name, message);
      }
    }
    if (exact) {
      camera.model_id = parsed_camera.model_id;
      camera.params = parsed_camera.params;
    } else {
      std::vector<RayPixelSample> samples;
      if (parsed_camera.model_id >= 0) {
        const int id = parsed_camera.model_id;
        const std::vector<double> params = parsed_camera.params;
        samples = SampleLensByProjection(
            [id, &params](const Eigen::Vector3d& ray, Eigen::Vector2d* pixel) {
              return ImageFromRay(id, params, ray, pixel);
            },
            camera.width, camera.height, sampling);
      } else {
        samples = parsed_camera.sample_lens(sampling);
      }
      if (samples.size() < 20) {
        throw CalibrationError(
            file_name, camera.name,
            "the lens images only " + std::to_string(samples.size()) +
                " sample rays inside the image; nothing to fit a model to");
      }
      ModelConversion conversion;
      try {
        conversion = target_id >= 0 ? FitModelToSamples(target_id, samples,
                                                         camera.width,
                                                         camera.height)
                                    : FitNearestModel(samples, camera.width,
                                                      camera.height);
      } catch (const std::invalid_argument& error) {
        throw CalibrationError(file_name, camera.name, error.what());
      }
      if (!conversion.check_message.empty()) {
        throw CalibrationError(file_name, camera.name,
                               "the fitted model is refused: " +
                                   conversion.check_message);
      }
      camera.model_id = conversion.model_id;
      camera.params = conversion.params;
      camera.fit = conversion.errors;
    }
    camera.model_name = calibration_internal::ModelName(camera.model_id);
    calibration.cameras.push_back(std::move(camera));
  }
  return calibration;
}

ImportedCalibration ImportCalibrationFile(
    const std::string& path, const CalibrationImportOptions& options) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw CalibrationError(path, "file", "cannot be read");
  std::ostringstream text;
  text << file.rdbuf();
  if (file.bad()) throw CalibrationError(path, "file", "cannot be read");
  return ImportCalibrationText(text.str(), path, options);
}

std::string FormatDouble(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

namespace {

std::string JsonNumbers(const std::vector<double>& values) {
  std::string text = "[";
  for (size_t i = 0; i < values.size(); ++i) {
    text += (i ? ", " : "") + FormatDouble(values[i]);
  }
  return text + "]";
}

}  // namespace

std::string RigConfigJson(const ImportedCalibration& calibration) {
  std::ostringstream config;
  config << "[\n  {\n    \"cameras\": [";
  for (size_t k = 0; k < calibration.cameras.size(); ++k) {
    const ImportedCamera& camera = calibration.cameras[k];
    config << (k ? "," : "") << "\n      {\n        \"image_prefix\": \""
           << camera.name << "/\",\n";
    if (k == 0) {
      config << "        \"ref_sensor\": true,\n";
    } else if (camera.cam_from_rig_rotation) {
      const Eigen::Quaterniond& q = *camera.cam_from_rig_rotation;
      const Eigen::Vector3d& t = camera.cam_from_rig_translation;
      config << "        \"cam_from_rig_rotation\": "
             << JsonNumbers({q.w(), q.x(), q.y(), q.z()})
             << ",\n        \"cam_from_rig_translation\": "
             << JsonNumbers({t.x(), t.y(), t.z()}) << ",\n";
    }
    config << "        \"camera_model_name\": \"" << camera.model_name
           << "\",\n        \"camera_params\": " << JsonNumbers(camera.params)
           << "\n      }";
  }
  config << "\n    ]\n  }\n]\n";
  return config.str();
}

std::string CamerasText(const ImportedCalibration& calibration) {
  std::ostringstream text;
  text << "# Camera list with one line of data per camera:\n"
          "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
          "# Number of cameras: "
       << calibration.cameras.size() << "\n";
  for (size_t k = 0; k < calibration.cameras.size(); ++k) {
    const ImportedCamera& camera = calibration.cameras[k];
    text << k + 1 << " " << camera.model_name << " " << camera.width << " "
         << camera.height;
    for (const double value : camera.params) text << " " << FormatDouble(value);
    text << "\n";
  }
  return text.str();
}

std::string ImageReaderOptions(const ImportedCamera& camera) {
  std::string params;
  for (size_t i = 0; i < camera.params.size(); ++i) {
    params += (i ? "," : "") + FormatDouble(camera.params[i]);
  }
  return "--ImageReader.camera_model " + camera.model_name +
         " --ImageReader.camera_params " + params;
}

}  // namespace sphera
