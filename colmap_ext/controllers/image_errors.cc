#include "colmap_ext/controllers/image_errors.h"

#include "colmap/scene/camera.h"
#include "colmap/sensor/models.h"
#include "colmap/util/string.h"
#include "colmap_ext/scene/camera_params_error.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>
#include <mutex>

namespace colmap {
namespace {

std::mutex& ErrorsMutex() {
  static std::mutex mutex;
  return mutex;
}

std::vector<std::string>& Errors() {
  static std::vector<std::string> errors;
  return errors;
}

}  // namespace

std::string ImageReaderCameraOptionsError(const std::string& camera_model,
                                          const std::string& camera_params) {
  if (!ExistsCameraModelWithName(camera_model)) {
    return "ImageReader.camera_model: unknown camera model '" + camera_model +
           "'";
  }
  Camera camera;
  camera.model_id = CameraModelNameToId(camera_model);
  for (std::string elem : StringSplit(camera_params, ",;")) {
    StringTrim(&elem);
    if (elem.empty()) {
      continue;
    }
    char* end = nullptr;
    const double value = std::strtod(elem.c_str(), &end);
    if (end != elem.c_str() + elem.size()) {
      return "ImageReader.camera_params: cannot read '" + elem +
             "' of '" + camera_params + "' as a number";
    }
    camera.params.push_back(value);
  }
  if (camera.params.empty()) {
    return "";
  }
  // Image size unknown (0 x 0) here: checked again per image.
  const std::string error = CameraParamsError(camera);
  return error.empty() ? "" : "ImageReader.camera_params: " + error;
}

void ReportImageError(const std::string& image_name,
                      const std::string& message) {
  std::lock_guard<std::mutex> lock(ErrorsMutex());
  Errors().push_back(image_name + ": " + message);
}

std::vector<std::string> ImageErrors() {
  std::lock_guard<std::mutex> lock(ErrorsMutex());
  return Errors();
}

void ClearImageErrors() {
  std::lock_guard<std::mutex> lock(ErrorsMutex());
  Errors().clear();
}

bool HasImageFileExtension(const std::string& path) {
  static const std::array<const char*, 16> kExtensions = {
      "jpg", "jpeg", "jpe", "jp2", "png", "tif", "tiff", "bmp",
      "pgm", "ppm", "pbm", "pnm", "webp", "exr", "hdr", "gif"};
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos) {
    return false;
  }
  std::string extension = path.substr(dot + 1);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return std::find(kExtensions.begin(), kExtensions.end(), extension) !=
         kExtensions.end();
}

}  // namespace colmap
