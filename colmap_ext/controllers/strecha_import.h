// Strecha et al.'s ground-truth `.camera` files as a COLMAP model (PINHOLE
// cameras, poses, no points), for `colmap strecha_importer`.
#pragma once

#include "colmap/scene/reconstruction.h"

#include <string>

namespace colmap {

// Reads every NAME.camera in `camera_path` (NAME is the image file name).
// Format, nine lines: K (3 rows), radial distortion (0 0 0), R (3 rows,
// camera-to-world), C (camera centre), width height. So
// cam_from_world = (R^T, -R^T C). Throws std::invalid_argument naming the
// file and line on malformed input.
Reconstruction ReadStrechaCameras(const std::string& camera_path);

}  // namespace colmap
