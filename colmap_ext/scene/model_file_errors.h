// Errors of the model readers that name the file they come from.
#pragma once

#include "colmap/scene/reconstruction.h"

#include <algorithm>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

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
// model or whose track does not hold it: what a points file that lost lines
// or track entries leaves behind (the readers accept each line on its own).
// Adding a point sets the reference of each of its track's observations, so
// the model is consistent when the images hold as many references as the
// tracks hold observations; only a model that is not is searched for the
// observation to name.
inline void CheckPoint3DReferences(const Reconstruction& reconstruction) {
  size_t num_references = 0;
  for (const auto& [image_id, image] : reconstruction.Images()) {
    num_references += image.NumPoints3D();
  }
  size_t num_observations = 0;
  for (const auto& [point3D_id, point3D] : reconstruction.Points3D()) {
    num_observations += point3D.track.Length();
  }
  if (num_references == num_observations) {
    return;
  }
  for (const auto& [image_id, image] : reconstruction.Images()) {
    for (point2D_t idx = 0; idx < image.NumPoints2D(); ++idx) {
      const point3D_t point3D_id = image.Point2D(idx).point3D_id;
      if (point3D_id == kInvalidPoint3DId) {
        continue;
      }
      const std::vector<TrackElement>* track =
          reconstruction.ExistsPoint3D(point3D_id)
              ? &reconstruction.Point3D(point3D_id).track.Elements()
              : nullptr;
      if (track == nullptr ||
          std::find(track->begin(), track->end(),
                    TrackElement(image_id, idx)) == track->end()) {
        throw std::runtime_error(
            "image " + std::to_string(image_id) + " observation " +
            std::to_string(idx) + " refers to 3D point " +
            std::to_string(point3D_id) +
            ", which is missing or whose track does not hold it");
      }
    }
  }
  throw std::runtime_error(
      "the tracks hold " + std::to_string(num_observations) +
      " observations but the images refer to points " +
      std::to_string(num_references) + " times (a repeated track entry)");
}

}  // namespace colmap
