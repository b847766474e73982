#include "colmap_ext/controllers/image_errors.h"

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

}  // namespace colmap
