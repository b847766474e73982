#include "colmap_ext/controllers/image_errors.h"

#include "colmap/scene/camera.h"
#include "colmap/sensor/models.h"
#include "colmap/util/string.h"
#include "colmap_ext/scene/camera_params_error.h"

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

namespace {

const char kTruncatedJpeg[] =
    "truncated JPEG: the file ends before its end-of-image marker (an "
    "interrupted copy?)";

// Why the bytes of a file that starts like a JPEG are not a whole JPEG
// image, or "". Walks its segments by their lengths and the entropy-coded
// data of each scan up to the next marker, as a decoder does, without
// decoding: a file cut anywhere ends before the end-of-image marker, and
// bytes overwritten in the middle leave data where a marker must be, or a
// marker that does not exist.
std::string JpegStructureError(const std::string& d) {
  const auto byte = [&d](size_t i) { return static_cast<unsigned char>(d[i]); };
  const size_t n = d.size();
  size_t i = 2;  // after the start-of-image marker
  while (true) {
    if (i >= n) {
      return kTruncatedJpeg;
    }
    if (byte(i) != 0xFF) {
      return "corrupt JPEG: data where a marker must be (byte " +
             std::to_string(i) + ")";
    }
    while (i < n && byte(i) == 0xFF) {
      ++i;  // fill bytes
    }
    if (i >= n) {
      return kTruncatedJpeg;
    }
    const unsigned char code = byte(i++);
    if (code == 0xD9) {
      return "";  // end of image; what follows (a camera's trailer) is not ours
    }
    if (code < 0xC0 || code == 0xD8 || (code >= 0xD0 && code <= 0xD7)) {
      return "corrupt JPEG: marker 0x" + StringPrintf("%02X", code) +
             " cannot be at byte " + std::to_string(i - 2);
    }
    if (i + 2 > n) {
      return kTruncatedJpeg;
    }
    const size_t length = (byte(i) << 8) | byte(i + 1);
    if (length < 2) {
      return "corrupt JPEG: a segment of length " + std::to_string(length);
    }
    i += length;
    if (i > n) {
      return kTruncatedJpeg;
    }
    if (code != 0xDA) {
      continue;
    }
    // A scan: entropy-coded data up to the next marker; 0xFF 0x00 is a
    // stuffed 0xFF, 0xFF 0xD0..0xD7 a restart marker.
    while (true) {
      const void* found = std::memchr(d.data() + i, 0xFF, n - i);
      if (found == nullptr) {
        return kTruncatedJpeg;
      }
      i = static_cast<const char*>(found) - d.data();
      if (i + 1 >= n) {
        return kTruncatedJpeg;
      }
      const unsigned char next = byte(i + 1);
      if (next == 0x00 || (next >= 0xD0 && next <= 0xD7)) {
        i += 2;
      } else if (next == 0xFF) {
        i += 1;
      } else {
        break;  // a marker
      }
    }
  }
}

// Why the bytes of a file that starts like a PNG are not a whole PNG, or "".
std::string PngStructureError(const std::string& d) {
  size_t i = 8;  // after the signature
  while (i + 8 <= d.size()) {
    const auto byte = [&d](size_t k) {
      return static_cast<uint32_t>(static_cast<unsigned char>(d[k]));
    };
    const uint64_t length =
        (byte(i) << 24) | (byte(i + 1) << 16) | (byte(i + 2) << 8) | byte(i + 3);
    if (d.compare(i + 4, 4, "IEND") == 0) {
      return "";
    }
    i += 12 + length;  // length, type, data, CRC
  }
  return "truncated PNG: the file ends before its last chunk (an "
         "interrupted copy?)";
}

}  // namespace

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
  if (data.size() >= 3 && data.compare(0, 3, "\xFF\xD8\xFF") == 0) {
    return JpegStructureError(data);
  }
  if (data.size() >= 8 && data.compare(0, 8, "\x89PNG\r\n\x1A\n") == 0) {
    return PngStructureError(data);
  }
  return "";
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
