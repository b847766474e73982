// Errors of the model readers that name the file they come from.
#pragma once

#include "colmap/scene/reconstruction.h"

#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <unordered_set>

namespace colmap {

// Runs read(), which reads the model file at `path`. Whatever it throws
// leaves as std::runtime_error "PATH: WHAT" (a truncated file, a value that
// does not parse, a reference to a missing camera or frame), so that the
// command can report it in one line and exit instead of aborting.
template <typename Read>
void ReadModelFile(const std::filesystem::path& path, Read&& read) {
  try {
    read();
  } catch (const std::exception& error) {
    throw std::runtime_error(path.string() + ": " + error.what());
  }
}

// Throws when an image's observation refers to a 3D point that is not in the
// model or whose track does not hold it: what a points3D file that lost
// lines or track entries leaves behind (the readers accept each line on its
// own).
inline void CheckPoint3DReferences(const Reconstruction& reconstruction) {
  std::unordered_set<uint64_t> observations;
  for (const auto& [point3D_id, point3D] : reconstruction.Points3D()) {
    for (const TrackElement& element : point3D.track.Elements()) {
      observations.insert((static_cast<uint64_t>(element.image_id) << 32) |
                          element.point2D_idx);
    }
  }
  for (const auto& [image_id, image] : reconstruction.Images()) {
    for (point2D_t idx = 0; idx < image.NumPoints2D(); ++idx) {
      const Point2D& point2D = image.Point2D(idx);
      if (point2D.HasPoint3D() &&
          !observations.count((static_cast<uint64_t>(image_id) << 32) | idx)) {
        throw std::runtime_error(
            "image " + std::to_string(image_id) + " observation " +
            std::to_string(idx) + " refers to 3D point " +
            std::to_string(point2D.point3D_id) +
            ", which is missing or whose track does not hold it");
      }
    }
  }
}

}  // namespace colmap
