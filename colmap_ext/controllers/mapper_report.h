// Per-image account of a mapper run: the model each database image ended in
// or, for an image in none, why the mapper could not use it. A user with a
// partly registered set learns which images failed and whether the cause is
// the image (no features), the matching (no verified pair) or the geometry
// (verified pairs, but no pose).
#pragma once

#include <string>
#include <vector>

#include "colmap/controllers/incremental_pipeline.h"
#include "colmap/scene/database.h"
#include "colmap/scene/reconstruction_manager.h"
#include "colmap_ext/scene/intrinsics_divergence.h"

namespace colmap {

struct MapperImageReport {
  std::string name;
  // Index of the model (the output sub-folder) that holds the image, -1 when
  // no model registered it.
  int model_index = -1;
  size_t num_keypoints = 0;
  // Other images this one shares a verified two-view geometry with, counting
  // only pairs with at least the mapper's min_num_matches inlier matches.
  size_t num_verified_pairs = 0;
  // Largest number of inlier matches with any other image.
  int max_inlier_matches = 0;
  // Empty for a registered image, else why it was not.
  std::string reason;
};

// One entry per database image, in name order. `image_names`: the mapper's
// image list (empty = every image); images outside it are left out.
std::vector<MapperImageReport> BuildMapperReport(
    const Database& database,
    const ReconstructionManager& reconstruction_manager,
    int min_num_matches,
    const std::vector<std::string>& image_names);

// Logs the models (images and points each) and every image that is in no
// model, with its reason (BuildMapperReport with the mapper's
// min_num_matches and image list); a split into several models is pointed
// out, and the cameras the mapper held (IncrementalPipeline::HeldCameras)
// are named.
void LogMapperReport(const Database& database,
                     const ReconstructionManager& reconstruction_manager,
                     const IncrementalPipelineOptions& mapper_options,
                     const std::vector<HeldCamera>& held_cameras);

}  // namespace colmap
