// Per-image errors of a pipeline run (feature extraction, import), so that a
// command can finish the images it can, then name the ones it could not and
// exit non-zero.
#pragma once

#include <string>
#include <vector>

namespace colmap {

// Thread-safe; records "image_name: message".
void ReportImageError(const std::string& image_name, const std::string& message);

std::vector<std::string> ImageErrors();

void ClearImageErrors();

// True for the file extensions of image formats COLMAP reads (case
// insensitive). A file without one in an image folder (a README, a .txt) is
// skipped, not an error.
bool HasImageFileExtension(const std::string& path);

}  // namespace colmap
