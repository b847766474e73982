// Bad camera input and unreadable images in feature extraction: every image
// that cannot be processed is named with the reason, the others are still
// extracted, and the command exits non-zero.
#pragma once

#include "colmap/controllers/image_reader.h"
#include "colmap/sensor/bitmap.h"

#include <filesystem>
#include <string>
#include <vector>

namespace colmap {

// Empty when --ImageReader.camera_model names a known model and
// --ImageReader.camera_params (if given) are numbers that fit it; otherwise a
// one-line message naming the option and what is wrong. Unlike COLMAP's
// CSVToVector, "nan" and "inf" are read as numbers so that they are reported
// as not finite rather than as unparsable.
std::string ImageReaderCameraOptionsError(const std::string& camera_model,
                                          const std::string& camera_params);

// Before feature extraction from `options.image_path` into the database at
// `database_path`: false (logged, naming the option) when the image path is
// not a folder; otherwise removes the cameras an interrupted extraction left
// (RemoveCamerasOfInterruptedExtraction) and clears the image errors.
bool PrepareFeatureExtraction(const std::filesystem::path& database_path,
                              const ImageReaderOptions& options);

// The image reader's read of an image: false, with the reason reported for
// `image_name`, when the file cannot be read whole (ImageFileError), the
// decoder fails, or the image is too small (TooSmallImageError).
bool ReadImageOrReport(const std::string& image_name,
                       const std::filesystem::path& path,
                       bool as_rgb,
                       Bitmap* bitmap);

// ImageReaderCameraOptionsError as a check: false, with the message logged,
// when the options are bad.
bool CheckImageReaderCameraOptions(const std::string& camera_model,
                                   const std::string& camera_params);

// Thread-safe; records "image_name: message", the first message of each
// image only.
void ReportImageError(const std::string& image_name, const std::string& message);

void ClearImageErrors();

// Reports the image as one that could not be processed when the reader's
// `status` says so: not for an image already in the database, nor for a
// file without an image file extension (HasImageFileExtension).
void ReportImageReaderStatus(const std::string& image_name,
                             ImageReader::Status status);

// "WxH pixels: too small to extract features from" for an image narrower
// or lower than 16 pixels, else empty.
std::string TooSmallImageError(int width, int height);

// EXIT_SUCCESS when no image error was reported since ClearImageErrors();
// otherwise logs them and returns EXIT_FAILURE.
int ImageErrorsExitStatus();

// True for the file extensions of image formats COLMAP reads (case
// insensitive). A file without one in an image folder (a README, a .txt) is
// skipped, not an error.
bool HasImageFileExtension(const std::string& path);

// Why the image file at `path` cannot be read whole, or "": missing (a
// dangling link), not a file, empty, or a JPEG or PNG whose structure ends
// early (truncated) or is broken (overwritten bytes). Decoders read such
// files with a warning at most and fill the missing part with gray, from
// which features would be extracted as if it were the scene. Reads the
// file once; does not decode it.
std::string ImageFileError(const std::filesystem::path& path);

// Reports every link under `image_path` whose target does not exist (the
// folder listing skips them as not files).
void ReportDanglingLinks(const std::filesystem::path& image_path);

}  // namespace colmap
