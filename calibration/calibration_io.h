// Import of the calibration files people have: Kalibr camchain YAML, OpenCV
// fisheye / omnidir / pinhole FileStorage files (YAML or XML), OCamCalib's
// calib_results.txt and Basalt's calibration JSON. Each camera becomes a
// camera of camera_models/registry.h, exactly where the file's model is one
// of ours and by a fit over the lens's field (calibration/model_conversion.h)
// where it is not; several cameras get their poses in a rig whose frame is
// the first camera's.
//
// Conventions (docs/camera_models.md, "Importing calibrations", states them
// per format):
// - camera frame: x right, y down, z forward, as in COLMAP and in all four
//   formats except OCamCalib (converted as camera_models/ocam.h says);
// - pixels: the files count from the centre of the upper-left pixel, COLMAP
//   from its corner, so every principal point gains 0.5 pixel;
// - poses: cam_from_rig maps points of the rig (first camera) frame into the
//   camera's frame; translations in the file's unit (metres for Kalibr and
//   Basalt).
//
// Every problem of a file is a CalibrationError whose message names the file
// and the field. No COLMAP headers.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "calibration/model_conversion.h"

namespace sphera {

enum class CalibrationFormat { kAuto, kKalibr, kOpenCV, kOCamCalib, kBasalt };

// "auto", "kalibr", "opencv", "ocamcalib", "basalt" (any letter case);
// throws std::invalid_argument listing them.
CalibrationFormat CalibrationFormatFromName(const std::string& name);
const char* CalibrationFormatName(CalibrationFormat format);

// what() is "FILE: FIELD: PROBLEM" on one line.
class CalibrationError : public std::runtime_error {
 public:
  CalibrationError(const std::string& file, const std::string& field,
                   const std::string& problem);
};

struct ImportedCamera {
  std::string name;          // the file's name of the camera (cam0, ...)
  std::string source_model;  // the file's model, e.g. "Kalibr pinhole-radtan"
  int width = 0;
  int height = 0;
  int model_id = -1;
  std::string model_name;
  std::vector<double> params;
  // Set when params come from a fit (the file's model is not one of ours, or
  // another model was asked for).
  std::optional<ModelFitErrors> fit;
  // cam_from_rig, the rig frame being the first camera's; absent for files
  // of one camera.
  std::optional<Eigen::Quaterniond> cam_from_rig_rotation;
  Eigen::Vector3d cam_from_rig_translation = Eigen::Vector3d::Zero();
};

struct ImportedCalibration {
  std::string file;
  CalibrationFormat format = CalibrationFormat::kAuto;
  std::vector<ImportedCamera> cameras;
  // What the importer assumed where the file was silent.
  std::vector<std::string> notes;
};

struct CalibrationImportOptions {
  CalibrationFormat format = CalibrationFormat::kAuto;
  // A model name of camera_models/registry.h to convert every camera to;
  // empty: the file's model where it is one of ours, else the nearest.
  std::string camera_model;
  // The lens's half field of view in degrees (a circular fisheye's image
  // circle); a fit to another model uses only the rays within it. 0: every
  // ray the image frame holds, up to the lens's fold.
  double half_field_deg = 0;
};

// Reads the file; throws CalibrationError.
ImportedCalibration ImportCalibrationFile(
    const std::string& path, const CalibrationImportOptions& options);

// The same for the file's content; file_name names it in messages (and its
// extension helps to detect the format).
ImportedCalibration ImportCalibrationText(
    const std::string& text, const std::string& file_name,
    const CalibrationImportOptions& options);

// The format of a file's content, or kAuto when it cannot be told.
CalibrationFormat DetectCalibrationFormat(const std::string& text);

// rig_configurator's rig_config.json: one rig of all cameras, the first the
// reference sensor, each camera's images under "NAME/". Needs poses.
std::string RigConfigJson(const ImportedCalibration& calibration);

// COLMAP's cameras.txt: camera i + 1 is calibration.cameras[i].
std::string CamerasText(const ImportedCalibration& calibration);

// "--ImageReader.camera_model M --ImageReader.camera_params p0,p1,..."
std::string ImageReaderOptions(const ImportedCamera& camera);

// Shortest text of a double that reads back to the same value.
std::string FormatDouble(double value);

}  // namespace sphera
