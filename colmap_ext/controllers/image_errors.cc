#include "colmap_ext/controllers/image_errors.h"

#include "colmap/scene/camera.h"
#include "colmap/sensor/models.h"
#include "colmap/util/file.h"
#include "colmap/util/logging.h"
#include "colmap/util/string.h"
#include "colmap_ext/image/image_file_structure.h"
#include "colmap_ext/scene/camera_params_error.h"
#include "colmap_ext/scene/unused_cameras.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
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
  const std::string prefix = image_name + ": ";
  for (const std::string& error : Errors()) {
    if (error.compare(0, prefix.size(), prefix) == 0) {
      return;
    }
  }
  Errors().push_back(prefix + message);
}

void ReportImageReaderStatus(const std::string& image_name,
                             const ImageReader::Status status) {
  // An image already in the database is not an error, nor a file of no
  // image type in the image folder (a README).
  if (status != ImageReader::Status::SUCCESS &&
      status != ImageReader::Status::IMAGE_EXISTS &&
      (status != ImageReader::Status::BITMAP_ERROR ||
       HasImageFileExtension(image_name))) {
    ReportImageError(image_name, ImageReader::StatusToString(status));
  }
}

std::string TooSmallImageError(const int width, const int height) {
  constexpr int kMinImageSize = 16;
  if (width < kMinImageSize || height < kMinImageSize) {
    return StringPrintf(
        "%dx%d pixels: too small to extract features from", width, height);
  }
  return "";
}

bool CheckImageReaderCameraOptions(const std::string& camera_model,
                                   const std::string& camera_params) {
  const std::string error =
      ImageReaderCameraOptionsError(camera_model, camera_params);
  if (!error.empty()) {
    LOG(ERROR) << error;
  }
  return error.empty();
}

bool PrepareFeatureExtraction(const std::filesystem::path& database_path,
                              const ImageReaderOptions& options) {
  if (!ExistsDir(options.image_path)) {
    LOG(ERROR) << "image_path: " << options.image_path << " is not a directory";
    return false;
  }
  RemoveCamerasOfInterruptedExtraction(database_path,
                                       options.existing_camera_id);
  ClearImageErrors();
  return true;
}

bool ReadImageOrReport(const std::string& image_name,
                       const std::filesystem::path& path,
                       const bool as_rgb,
                       Bitmap* bitmap) {
  std::string error = ImageFileError(path);
  if (error.empty()) {
    if (!bitmap->Read(path, as_rgb)) {
      return false;  // The reader's status names the image.
    }
    error = TooSmallImageError(bitmap->Width(), bitmap->Height());
  }
  if (!error.empty()) {
    ReportImageError(image_name, error);
    return false;
  }
  return true;
}

int ImageErrorsExitStatus() {
  std::lock_guard<std::mutex> lock(ErrorsMutex());
  if (Errors().empty()) {
    return EXIT_SUCCESS;
  }
  LOG(ERROR) << Errors().size()
             << " image(s) could not be processed (the others were):";
  for (const std::string& image_error : Errors()) {
    LOG(ERROR) << "  " << image_error;
  }
  return EXIT_FAILURE;
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

std::string ImageFileError(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    return std::filesystem::is_symlink(path, error)
               ? "a link to a file that does not exist"
               : "the file does not exist";
  }
  if (!std::filesystem::is_regular_file(path, error)) {
    return "not a file";
  }
  if (std::filesystem::file_size(path, error) == 0) {
    return "empty file (0 bytes)";
  }
  std::ifstream file(path, std::ios::binary);
  std::string data((std::istreambuf_iterator<char>(file)),
                   std::istreambuf_iterator<char>());
  if (!file.good() && !file.eof()) {
    return "cannot be read";
  }
  return ImageBytesError(data);
}

void ReportDanglingLinks(const std::filesystem::path& image_path) {
  std::error_code error;
  for (auto it = std::filesystem::recursive_directory_iterator(image_path, error);
       !error && it != std::filesystem::recursive_directory_iterator();
       it.increment(error)) {
    if (it->is_symlink(error) && !std::filesystem::exists(it->path(), error)) {
      ReportImageError(
          std::filesystem::relative(it->path(), image_path, error).string(),
          "a link to a file that does not exist");
    }
  }
}

}  // namespace colmap
