#include "colmap_ext/controllers/image_errors.h"

#include <algorithm>
#include <array>
#include <cctype>
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
