// Model files: errors of the readers that name the file they come from, and
// writes that replace a model only once the new one is complete.
#pragma once

#include "colmap/scene/reconstruction.h"
#include "colmap/scene/reconstruction_io_binary.h"
#include "colmap/scene/reconstruction_io_text.h"
#include "colmap_ext/util/file_output.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <istream>
#include <stdexcept>
#include <string>
#include <utility>
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

// Throws unless `stream` holds at least `count` more items of
// `bytes_per_item` bytes: a count read from a damaged file must not make
// the reader allocate for more than the file can hold. `what` names the
// count in the message.
inline void CheckCountFits(std::istream& stream, uint64_t count,
                           uint64_t bytes_per_item, const std::string& what) {
  const std::streampos here = stream.tellg();
  stream.seekg(0, std::ios::end);
  const std::streampos end = stream.tellg();
  stream.seekg(here);
  if (here < 0 || end < 0) {
    return;  // not seekable: the reads fail at the end instead
  }
  const uint64_t left = static_cast<uint64_t>(end - here);
  if (count > left / bytes_per_item) {
    throw std::runtime_error(what + " is " + std::to_string(count) +
                             ", more than the " + std::to_string(left) +
                             " bytes left in the file can hold");
  }
}

// Throws when a camera parameter, a sensor or frame pose or a 3D point of
// the model holds a value that is not finite (NaN, infinity): binary files
// are read as they are, and such a value would poison every later step.
// Called after each file is read, so that the file that brought the value
// is the one named.
inline void CheckFiniteValues(const Reconstruction& reconstruction) {
  const auto finite_pose = [](const std::optional<Rigid3d>& pose) {
    return !pose.has_value() ||
           (pose->rotation().coeffs().allFinite() &&
            pose->translation().allFinite());
  };
  for (const auto& [camera_id, camera] : reconstruction.Cameras()) {
    for (size_t i = 0; i < camera.params.size(); ++i) {
      if (!std::isfinite(camera.params[i])) {
        throw std::runtime_error("camera " + std::to_string(camera_id) +
                                 ": parameter " + std::to_string(i + 1) +
                                 " is not finite");
      }
    }
  }
  for (const auto& [rig_id, rig] : reconstruction.Rigs()) {
    for (const auto& [sensor_id, sensor_from_rig] : rig.NonRefSensors()) {
      if (!finite_pose(sensor_from_rig)) {
        throw std::runtime_error("rig " + std::to_string(rig_id) +
                                 ": a sensor pose is not finite");
      }
    }
  }
  for (const auto& [frame_id, frame] : reconstruction.Frames()) {
    if (!finite_pose(frame.MaybeRigFromWorld())) {
      throw std::runtime_error("frame " + std::to_string(frame_id) +
                               ": its pose is not finite");
    }
  }
  for (const auto& [point3D_id, point3D] : reconstruction.Points3D()) {
    if (!point3D.xyz.allFinite()) {
      throw std::runtime_error("3D point " + std::to_string(point3D_id) +
                               ": its position is not finite");
    }
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

// ReadModelFile, then CheckFiniteValues: for the binary files, which hold
// values as they are.
template <typename Read>
void ReadFiniteModelFile(const std::filesystem::path& path,
                         const Reconstruction& reconstruction,
                         Read&& read) {
  ReadModelFile(path, [&] {
    read();
    CheckFiniteValues(reconstruction);
  });
}

// Throws when the pose an image record of images.bin holds is not finite:
// unused when frames.bin holds the poses, but a damaged file all the same.
inline void CheckFinitePose(image_t image_id, const Rigid3d& cam_from_world) {
  if (!cam_from_world.rotation().coeffs().allFinite() ||
      !cam_from_world.translation().allFinite()) {
    throw std::runtime_error("image " + std::to_string(image_id) +
                             ": its pose is not finite");
  }
}

// The frame of `image_id` in the map of images to frames that frames.bin
// gives; throws when the image is in none.
template <typename ImageToFrame>
auto* FrameOfImage(const ImageToFrame& image_to_frame, image_t image_id) {
  const auto frame_it = image_to_frame.find(image_id);
  if (frame_it == image_to_frame.end()) {
    throw std::runtime_error("image " + std::to_string(image_id) +
                             " is in no frame of frames.bin");
  }
  return frame_it->second;
}

// Reads the rest of a line of points3D.txt, the track of point
// `point3D_id`: pairs IMAGE_ID POINT2D_IDX. Throws unless it is a list of
// such pairs.
inline void ReadTrackText(std::istream& line_stream,
                          point3D_t point3D_id,
                          Track* track) {
  std::vector<uint64_t> track_values;
  uint64_t value;
  while (line_stream >> value) {
    track_values.push_back(value);
  }
  if (!line_stream.eof() || track_values.size() % 2 != 0) {
    throw std::runtime_error(
        "point " + std::to_string(point3D_id) +
        ": the track is not a list of (IMAGE_ID, POINT2D_IDX) pairs");
  }
  for (size_t i = 0; i < track_values.size(); i += 2) {
    track->AddElement(static_cast<image_t>(track_values[i]),
                      static_cast<point2D_t>(track_values[i + 1]));
  }
}

// Writes the model files of `reconstruction` into the folder `path`, text
// or binary, under temporary names renamed into place once all are
// complete (WriteFilesAtomically).
inline void WriteModelFiles(const Reconstruction& reconstruction,
                            const std::filesystem::path& path,
                            bool binary) {
  using P = const std::filesystem::path&;
  const Reconstruction& r = reconstruction;
  if (binary) {
    WriteFilesAtomically(
        path,
        {{"rigs.bin", [&r](P p) { WriteRigsBinary(r, p); }},
         {"cameras.bin", [&r](P p) { WriteCamerasBinary(r, p); }},
         {"frames.bin", [&r](P p) { WriteFramesBinary(r, p); }},
         {"images.bin", [&r](P p) { WriteImagesBinary(r, p); }},
         {"points3D.bin", [&r](P p) { WritePoints3DBinary(r, p); }}});
  } else {
    WriteFilesAtomically(
        path,
        {{"rigs.txt", [&r](P p) { WriteRigsText(r, p); }},
         {"cameras.txt", [&r](P p) { WriteCamerasText(r, p); }},
         {"frames.txt", [&r](P p) { WriteFramesText(r, p); }},
         {"images.txt", [&r](P p) { WriteImagesText(r, p); }},
         {"points3D.txt", [&r](P p) { WritePoints3DText(r, p); }}});
  }
}

}  // namespace colmap
