// The readers of calibration_io.h, one per format, and the checks they share.
// A reader returns the cameras as the file describes them; ImportCalibration*
// (calibration_io.cc) turns them into cameras of ours.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "calibration/calibration_io.h"
#include "calibration/lens_projections.h"
#include "calibration/model_conversion.h"

namespace sphera {
namespace calibration_internal {

// A camera of a file, before conversion.
struct ParsedCamera {
  std::string name;
  std::string source_model;
  int width = 0;
  int height = 0;
  // The file's model when it is one of ours (model_id >= 0), exactly.
  int model_id = -1;
  std::vector<double> params;
  // Otherwise the samples of the lens, for a fit.
  std::function<std::vector<RayPixelSample>(const LensSamplingOptions&)>
      sample_lens;
  std::optional<Eigen::Quaterniond> cam_from_rig_rotation;
  Eigen::Vector3d cam_from_rig_translation = Eigen::Vector3d::Zero();
};

struct ParsedFile {
  std::vector<ParsedCamera> cameras;
  std::vector<std::string> notes;
};

ParsedFile ReadKalibr(const std::string& text, const std::string& file);
ParsedFile ReadOpenCV(const std::string& text, const std::string& file);
ParsedFile ReadOCamCalib(const std::string& text, const std::string& file);
ParsedFile ReadBasalt(const std::string& text, const std::string& file);

// -- checks shared by the readers --------------------------------------------

// Largest image side, focal length (as a multiple of the larger image side)
// and rig baseline (file units, metres) that are not absurd.
inline constexpr int kMaxImageSide = 100000;
inline constexpr double kMaxFocalPerSide = 100;
inline constexpr double kMaxTranslation = 1000;

// A finite number, else CalibrationError naming the field.
double FiniteNumber(const std::string& file, const std::string& field,
                    double value);
// A whole number of pixels in [1, kMaxImageSide].
int ImageSide(const std::string& file, const std::string& field, double value);
// fx, fy in (0, kMaxFocalPerSide * max(w, h)]; the principal point within
// one image size of the image.
void CheckPinhole(const std::string& file, const std::string& field,
                  double fx, double fy, double cx, double cy, int width,
                  int height);
// Builds the camera of the lens: exact when model_id >= 0, else by samples.
ParsedCamera LensCamera(const std::string& name,
                        const std::string& source_model, int width,
                        int height, const GenericLens& lens);
// The rotation of a file's 3x3 matrix: orthonormal within 1e-3 with
// determinant 1 (then made exactly so), else CalibrationError.
Eigen::Quaterniond RotationOfMatrix(const std::string& file,
                                    const std::string& field,
                                    const Eigen::Matrix3d& matrix);
void CheckTranslation(const std::string& file, const std::string& field,
                      const Eigen::Vector3d& translation);

}  // namespace calibration_internal
}  // namespace sphera
