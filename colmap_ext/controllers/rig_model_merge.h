// Models of one mapper run that share a frame of a multi-lens rig, joined
// into one. A 360° camera that mostly rotates between captures splits into
// models that overlap by a frame: the frames on either side see the shared
// frame's scene but too few of the other side's points to register. Upstream
// merges models only through three or more common images (a similarity from
// their centres); a shared rig frame already fixes the rotation and position
// of one model in the other, and the 3D points both triangulated from the
// frame's keypoints give the scale (estimators/similarity_alignment.h).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "colmap/controllers/incremental_pipeline.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/scene/reconstruction_manager.h"
#include "colmap_ext/scene/intrinsics_divergence.h"

namespace colmap {

// Frames registered in both models whose rig has several sensors (the
// lenses of a multi-camera rig; DivergedCameraHold's criterion too).
std::vector<frame_t> SharedRigFrames(const Reconstruction& reconstruction1,
                                     const Reconstruction& reconstruction2);

// Merges `src` into `tgt` through their shared rig frames, then runs the
// mapper's global bundle adjustment over the whole (the intrinsics of
// `held_cameras` constant) and its point filter. False, `tgt` unchanged and
// `why` said, when they share no rig frame, fewer than `min_common_points`
// 3D points of both models come from the same keypoints of a shared frame,
// or the merged model does not hold together: fewer than 80% of the two
// models' observations survive the filter, or the mean reprojection error
// grows past 1.5 times the larger of the two models' own (plus 0.1 px).
bool MergeRigModels(const IncrementalPipelineOptions& options,
                    const std::vector<HeldCamera>& held_cameras,
                    int min_common_points,
                    const Reconstruction& src,
                    Reconstruction& tgt,
                    std::string* why);

// After a mapper run (`--Mapper.merge_rig_models`): merges, largest model
// first, every pair of models that share a rig frame, until no pair does, and
// writes the models again to `output_path`/0, 1, ... (the mapper wrote
// `num_written` of them as they finished; the folders of models merged away
// are removed). Returns the number of merges.
size_t MergeModelsSharingRigFrames(
    const IncrementalPipelineOptions& options,
    const std::vector<HeldCamera>& held_cameras,
    const std::filesystem::path& output_path,
    size_t num_written,
    ReconstructionManager& reconstruction_manager);

}  // namespace colmap
