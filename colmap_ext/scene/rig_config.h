// SPHERA's reading and checking of rig_configurator's configuration: errors
// that name the file and the camera, lenses named by a suffix, frames that
// lack a lens's image, and lenses that feature extraction gave one camera.
// COLMAP's ReadRigConfig and ApplyRigConfig call into this.
#pragma once

#include "colmap/scene/database.h"
#include "colmap/scene/image.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/scene/rig.h"

#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace colmap {

// The rig configuration of the JSON file at `path` (the format of COLMAP's
// ReadRigConfig, plus "image_suffix"). Throws std::invalid_argument
// "rig config PATH: WHAT" naming the camera: lists of the wrong length, text
// where numbers belong, values that are not finite, a rotation without a
// translation (or the reverse), a zero rotation, an unknown camera model, a
// parameter count that does not fit the model, no or two reference sensors.
std::vector<RigConfig> ReadCheckedRigConfig(const std::filesystem::path& path);

// rig_configurator: reads the rig configuration at `rig_config_path`
// (ReadRigConfig) before it opens the database at `database_path`, and
// applies it (ApplyRigConfig) in one transaction, so that a failure leaves
// the database as it was.
void ConfigureRigs(const std::filesystem::path& rig_config_path,
                   const std::filesystem::path& database_path,
                   Reconstruction* reconstruction,
                   bool allow_incomplete_frames);

// The frame name of `image_name` for a lens whose images are named
// PREFIX FRAME SUFFIX (prefix, suffix or both given), or nothing when the
// name is not of that lens.
std::optional<std::string> RigFrameName(const std::string& image_name,
                                        const RigConfig::RigCamera& lens);

// Throws std::invalid_argument naming the image and both cameras with their
// sizes when `image` does not have `lens_camera_id`, the camera of the other
// images of the lens with `image_prefix`: a lens needs one camera.
void CheckOneCameraPerLens(const Database& database,
                           camera_t lens_camera_id,
                           const Image& image,
                           const std::string& image_prefix);

// Which image each frame of one rig has of each of its lenses, while
// ApplyRigConfig assigns the database's images to the rig's lenses.
class RigFrameLenses {
 public:
  explicit RigFrameLenses(const RigConfig& config);

  // When `image` is named as an image of lens `lens_idx` (RigFrameName),
  // records it as its frame's image of that lens and returns the frame's
  // name. Throws std::invalid_argument when the frame has an image of that
  // lens already.
  std::optional<std::string> Add(size_t lens_idx, const Image& image);

  // The camera of lens `lens_idx` in the rig, from `camera_id`, the camera
  // of its images (none: throws std::invalid_argument naming the lens's
  // prefix and suffix). A camera that another lens of the rig has already
  // (`rig_camera_ids`, to which the result is added) is split off
  // (MoveToOwnCamera); the config's intrinsics, if it has any, are written
  // to the database and the reconstruction.
  camera_t ConfigureCamera(size_t lens_idx,
                           const std::optional<camera_t>& camera_id,
                           std::set<camera_t>* rig_camera_ids,
                           Database& database,
                           Reconstruction* reconstruction);

  // Gives lens `lens_idx`, whose images have the camera `shared_camera_id`
  // of another lens of the rig (all lenses extracted as one camera, e.g.
  // NAME_1.JPG ... NAME_8.JPG in one folder), a copy of that camera in the
  // database and moves the lens's images to it; returns the copy's id.
  // With a reconstruction (rig_configurator --input_path), whose cameras
  // cannot be split, throws std::invalid_argument instead.
  camera_t MoveToOwnCamera(size_t lens_idx,
                           camera_t shared_camera_id,
                           Database& database,
                           const Reconstruction* reconstruction);

  // Throws std::invalid_argument naming the first frame without an image
  // of a lens, the lens and the image name expected.
  void CheckComplete() const;

  // The image's data id, with the camera MoveToOwnCamera moved it to.
  data_t DataId(const Image& image) const;

 private:
  const RigConfig& config_;
  std::map<std::string, std::vector<const Image*>> frame_lenses_;
  std::map<image_t, camera_t> moved_images_;
};

}  // namespace colmap
