// The files SPHERA's renderer writes and its commands read: image files
// recognised by the extension of their names, JSON number lists and range
// maps. Header-only
// (standard library and OpenCV's codec constants), so that the COLMAP
// commands share these definitions without linking the renderer.
#pragma once

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

namespace sphera {

// The extension of `name` in lower case, with its dot ("" without one).
inline std::string LowerCaseExtension(const std::string& name) {
  const size_t dot = name.find_last_of('.');
  const size_t slash = name.find_last_of("/\\");
  if (dot == std::string::npos ||
      (slash != std::string::npos && dot < slash)) {
    return "";
  }
  std::string extension = name.substr(dot);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// The extensions (lower case) of the image files SPHERA reads: what OpenCV
// decodes, and Insta360's .insp stills, which are JPEG files.
inline const std::vector<std::string>& ImageFileExtensions() {
  static const std::vector<std::string> extensions = {
      ".jpg", ".jpeg", ".png", ".tif", ".tiff", ".bmp",
      ".pgm", ".ppm",  ".pnm", ".webp", ".insp"};
  return extensions;
}

inline bool IsImageFileName(const std::string& name) {
  const std::string extension = LowerCaseExtension(name);
  const auto& known = ImageFileExtensions();
  return std::find(known.begin(), known.end(), extension) != known.end();
}

// The extension that tells OpenCV's encoder the format of a file named
// `name` (".insp" stills are JPEG files).
inline std::string EncoderExtension(const std::string& name) {
  const std::string extension = LowerCaseExtension(name);
  return extension == ".insp" ? ".jpg" : extension;
}

inline bool IsJpegFileName(const std::string& name) {
  const std::string extension = EncoderExtension(name);
  return extension == ".jpg" || extension == ".jpeg";
}

inline bool IsPngFileName(const std::string& name) {
  return LowerCaseExtension(name) == ".png";
}

// cv::imwrite's parameters for a file named `name`: PNG compression 3, or
// for JPEG files the quality `jpeg_quality` (1..100; 0 or less: 95); none for
// other formats.
inline std::vector<int> ImageWriteParams(const std::string& name,
                                         int jpeg_quality) {
  if (IsPngFileName(name)) {
    return {cv::IMWRITE_PNG_COMPRESSION, 3};
  }
  if (IsJpegFileName(name)) {
    return {cv::IMWRITE_JPEG_QUALITY, jpeg_quality > 0 ? jpeg_quality : 95};
  }
  return {};
}

// "[v0, v1, ...]" with every value to full double precision: the number
// lists of the JSON files (rig configs, reports) SPHERA writes.
inline std::string JsonList(const std::vector<double>& values) {
  std::ostringstream out;
  out << std::setprecision(17) << "[";
  for (size_t i = 0; i < values.size(); ++i) {
    out << (i ? ", " : "") << values[i];
  }
  out << "]";
  return out.str();
}

// A range map (NAME.depth.bin beside a rendered image): int32 width, int32
// height, then width*height float32 ranges in metres along the pixel-centre
// rays, row-major (row 0 first), all little-endian; 0 where nothing is hit.
struct RangeMap {
  int width = 0;
  int height = 0;
  std::vector<float> ranges;

  float At(int x, int y) const {
    return ranges[static_cast<size_t>(y) * width + x];
  }
};

// Reads the range map at `path`: "" or why it is not one (unreadable, a
// header of another size than 1..65536 per side, fewer or more bytes than
// its size says, a range that is negative or not finite).
inline std::string ReadRangeMap(const std::string& path, RangeMap* map) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    return "cannot be read";
  }
  int32_t size[2];
  if (!file.read(reinterpret_cast<char*>(size), sizeof(size))) {
    return "is shorter than its 8-byte header";
  }
  if (size[0] <= 0 || size[1] <= 0 || size[0] > 65536 || size[1] > 65536) {
    return "declares the size " + std::to_string(size[0]) + "x" +
           std::to_string(size[1]);
  }
  map->width = size[0];
  map->height = size[1];
  map->ranges.resize(static_cast<size_t>(size[0]) * size[1]);
  if (!file.read(reinterpret_cast<char*>(map->ranges.data()),
                 static_cast<std::streamsize>(map->ranges.size() *
                                              sizeof(float)))) {
    return "holds fewer than its " + std::to_string(map->ranges.size()) +
           " ranges";
  }
  if (file.peek() != std::ifstream::traits_type::eof()) {
    return "holds more bytes than its " + std::to_string(map->ranges.size()) +
           " ranges";
  }
  for (size_t i = 0; i < map->ranges.size(); ++i) {
    if (!std::isfinite(map->ranges[i]) || map->ranges[i] < 0) {
      return "has the range " + std::to_string(map->ranges[i]) +
             " at pixel (" + std::to_string(i % map->width) + ", " +
             std::to_string(i / map->width) + ")";
    }
  }
  return "";
}

// Writes `map` in the format above; false if the file cannot be written.
inline bool WriteRangeMap(const std::string& path, const RangeMap& map) {
  std::ofstream file(path, std::ios::binary);
  const int32_t size[2] = {map.width, map.height};
  file.write(reinterpret_cast<const char*>(size), sizeof(size));
  file.write(reinterpret_cast<const char*>(map.ranges.data()),
             static_cast<std::streamsize>(map.ranges.size() * sizeof(float)));
  file.close();
  return static_cast<bool>(file);
}

}  // namespace sphera
