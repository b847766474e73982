// OCamCalib's calib_results.txt (the C export of the MATLAB toolbox): comment
// lines starting with '#', and five lines of numbers in this order:
//   N a0 a1 ... a(N-1)    polynomial of the direct mapping (cam2world)
//   M p0 ... p(M-1)       inverse polynomial (world2cam; not used)
//   xc yc                 centre: row and column, from 0 (C convention)
//   c d e                 affine parameters
//   height width          image size
// OCAM takes them as camera_models/ocam.h says: cx = yc + 0.5 and
// cy = xc + 0.5 (COLMAP counts from the corner of the first pixel), c, d, e
// unchanged, (a0, a2, a3, a4) when the polynomial has degree 4 or less and
// a1 = 0 (as OCamCalib fits it); another polynomial is fitted.
#include <cstdlib>
#include <sstream>

#include "calibration/calibration_readers.h"
#include "camera_models/registry.h"

namespace sphera {
namespace calibration_internal {
namespace {

constexpr const char* kLineNames[] = {
    "polynomial coefficients", "inverse polynomial coefficients", "center",
    "affine parameters", "image size"};

std::vector<double> LineNumbers(const std::string& file,
                                const std::string& field,
                                const std::string& line) {
  std::istringstream words(line);
  std::vector<double> values;
  std::string word;
  while (words >> word) {
    char* end = nullptr;
    const double value = std::strtod(word.c_str(), &end);
    if (end == word.c_str() || *end != '\0') {
      throw CalibrationError(file, field,
                             "\"" + word.substr(0, 40) + "\" is not a number");
    }
    values.push_back(FiniteNumber(
        file, field + "[" + std::to_string(values.size()) + "]", value));
  }
  return values;
}

// A counted list "N v0 ... v(N-1)".
std::vector<double> CountedList(const std::string& file,
                                const std::string& field,
                                const std::vector<double>& values) {
  if (values.empty() || values[0] != std::floor(values[0]) || values[0] < 1 ||
      values[0] > 64 || values.size() != static_cast<size_t>(values[0]) + 1) {
    throw CalibrationError(file, field,
                           "must be a count N followed by N numbers");
  }
  return std::vector<double>(values.begin() + 1, values.end());
}

}  // namespace

ParsedFile ReadOCamCalib(const std::string& text, const std::string& file) {
  std::vector<std::vector<double>> lines;
  std::istringstream stream(text);
  std::string line;
  while (std::getline(stream, line)) {
    const size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    if (lines.size() == 5) {
      throw CalibrationError(file, "image size",
                             "more lines of numbers follow the image size");
    }
    lines.push_back(LineNumbers(file, kLineNames[lines.size()], line));
  }
  if (lines.size() < 5) {
    throw CalibrationError(file, kLineNames[lines.size()], "missing");
  }
  const std::vector<double> pol = CountedList(file, kLineNames[0], lines[0]);
  CountedList(file, kLineNames[1], lines[1]);
  if (lines[2].size() != 2) {
    throw CalibrationError(file, kLineNames[2], "must be xc yc (row, column)");
  }
  if (lines[3].size() != 3) {
    throw CalibrationError(file, kLineNames[3], "must be c d e");
  }
  if (lines[4].size() != 2) {
    throw CalibrationError(file, kLineNames[4], "must be height width");
  }
  const int height = ImageSide(file, "image size height", lines[4][0]);
  const int width = ImageSide(file, "image size width", lines[4][1]);

  OCamPolynomialLens lens;
  lens.pol = pol;
  lens.cy = lines[2][0] + 0.5;
  lens.cx = lines[2][1] + 0.5;
  lens.c = lines[3][0];
  lens.d = lines[3][1];
  lens.e = lines[3][2];
  if (lens.cx < -width || lens.cx > 2.0 * width || lens.cy < -height ||
      lens.cy > 2.0 * height) {
    throw CalibrationError(file, kLineNames[2],
                           "the centre is more than an image size outside "
                           "the image");
  }
  if (!(pol[0] < 0)) {
    throw CalibrationError(file, kLineNames[0],
                           "a0 = " + FormatDouble(pol[0]) +
                               " must be negative (OCamCalib's sign)");
  }
  if (-pol[0] > kMaxFocalPerSide * std::max(width, height)) {
    throw CalibrationError(file, kLineNames[0],
                           "a0 = " + FormatDouble(pol[0]) +
                               " is not a focal length for this image");
  }

  ParsedCamera camera;
  camera.name = "cam0";
  camera.source_model =
      "OCamCalib polynomial of degree " + std::to_string(pol.size() - 1);
  camera.width = width;
  camera.height = height;
  if (pol.size() <= 5 && (pol.size() < 2 || pol[1] == 0)) {
    camera.model_id = static_cast<int>(ModelId::kOCam);
    camera.params = {lens.cx, lens.cy, lens.c, lens.d, lens.e, pol[0], 0, 0,
                     0};
    for (size_t i = 2; i < pol.size(); ++i) camera.params[4 + i] = pol[i];
  } else {
    camera.sample_lens = [lens, width,
                          height](const LensSamplingOptions& sampling) {
      return SampleLensByUnprojection(
          [&lens](const Eigen::Vector2d& pixel, Eigen::Vector3d* ray) {
            return lens.RayFromImage(pixel, ray);
          },
          Eigen::Vector2d(lens.cx, lens.cy), width, height, sampling);
    };
  }
  ParsedFile parsed;
  parsed.cameras.push_back(std::move(camera));
  return parsed;
}

}  // namespace calibration_internal
}  // namespace sphera
