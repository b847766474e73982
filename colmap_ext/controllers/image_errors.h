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

}  // namespace colmap
