#include "colmap_ext/controllers/strecha_import.h"

#include "colmap/util/logging.h"
#include "colmap/util/string.h"

#include "camera_models/intrinsics_check.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace colmap {
namespace {

// Reads `count` numbers from the next non-empty line of `file`.
std::vector<double> ReadNumbers(std::istream& file,
                                const std::string& path,
                                int* line_number,
                                size_t count) {
  std::string line;
  while (std::getline(file, line)) {
    ++*line_number;
    StringTrim(&line);
    if (line.empty()) {
      continue;
    }
    // strtod, unlike operator>>, reads "nan" and "inf": they are named as
    // such rather than as a short line.
    std::istringstream stream(line);
    std::vector<double> numbers;
    std::string token;
    while (stream >> token) {
      char* end = nullptr;
      const double value = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0') {
        throw std::invalid_argument(StringPrintf(
            "%s:%d: '%s' is not a number", path.c_str(), *line_number,
            token.c_str()));
      }
      if (!std::isfinite(value)) {
        throw std::invalid_argument(StringPrintf(
            "%s:%d: '%s' is not a finite number", path.c_str(), *line_number,
            token.c_str()));
      }
      numbers.push_back(value);
    }
    if (numbers.size() != count) {
      throw std::invalid_argument(StringPrintf(
          "%s:%d: expected %d numbers", path.c_str(), *line_number,
          static_cast<int>(count)));
    }
    return numbers;
  }
  throw std::invalid_argument(StringPrintf(
      "%s: ends after line %d, expected 9 lines", path.c_str(), *line_number));
}

}  // namespace

Reconstruction ReadStrechaCameras(const std::string& camera_path) {
  const std::string kSuffix = ".camera";
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(camera_path)) {
    const std::string path = entry.path().string();
    if (entry.is_regular_file() && path.size() > kSuffix.size() &&
        path.compare(path.size() - kSuffix.size(), kSuffix.size(), kSuffix) ==
            0) {
      files.push_back(path);
    }
  }
  std::sort(files.begin(), files.end());
  Reconstruction reconstruction;
  for (const std::string& path : files) {
    std::ifstream file(path);
    if (!file) {
      throw std::invalid_argument("cannot open " + path);
    }
    int line_number = 0;
    Eigen::Matrix3d K;
    for (int row = 0; row < 3; ++row) {
      const std::vector<double> values =
          ReadNumbers(file, path, &line_number, 3);
      K.row(row) = Eigen::Vector3d(values[0], values[1], values[2]);
    }
    ReadNumbers(file, path, &line_number, 3);  // radial distortion, zero
    Eigen::Matrix3d world_from_cam_rotation;
    for (int row = 0; row < 3; ++row) {
      const std::vector<double> values =
          ReadNumbers(file, path, &line_number, 3);
      world_from_cam_rotation.row(row) =
          Eigen::Vector3d(values[0], values[1], values[2]);
    }
    const std::vector<double> center = ReadNumbers(file, path, &line_number, 3);
    const std::vector<double> size = ReadNumbers(file, path, &line_number, 2);
    if (std::string error = sphera::ImageSizeError(size[0], size[1]);
        !error.empty() ||
        !(error = sphera::PinholeMatrixError(K, size[0], size[1])).empty()) {
      throw std::invalid_argument(path + ": " + error);
    }
    if (std::abs(world_from_cam_rotation.determinant() - 1) > 1e-3) {
      throw std::invalid_argument(path + ": R is not a rotation");
    }

    Camera camera;
    camera.camera_id = static_cast<camera_t>(reconstruction.NumCameras() + 1);
    camera.model_id = CameraModelId::kPinhole;
    camera.width = static_cast<size_t>(size[0]);
    camera.height = static_cast<size_t>(size[1]);
    camera.params = {K(0, 0), K(1, 1), K(0, 2), K(1, 2)};
    reconstruction.AddCameraWithTrivialRig(camera);

    // Orthonormalise R (the files carry six digits).
    const Eigen::Quaterniond world_from_cam(world_from_cam_rotation);
    const Eigen::Quaterniond cam_from_world =
        world_from_cam.normalized().inverse();
    Image image;
    image.SetImageId(static_cast<image_t>(reconstruction.NumImages() + 1));
    image.SetCameraId(camera.camera_id);
    std::string name = std::filesystem::path(path).filename().string();
    name = name.substr(0, name.size() - kSuffix.size());
    image.SetName(name);
    reconstruction.AddImageWithTrivialFrame(
        std::move(image),
        Rigid3d(cam_from_world,
                -(cam_from_world *
                  Eigen::Vector3d(center[0], center[1], center[2]))));
  }
  if (reconstruction.NumImages() == 0) {
    throw std::invalid_argument("no *.camera files in " + camera_path);
  }
  return reconstruction;
}

}  // namespace colmap
