// The incremental mapper's initial pair when its images are lenses of rig
// frames (a 360° camera's lenses configured by rig_configurator): one
// attempt per pair of frames, on the matches of all their lenses, so that
// the lenses' offsets in the rig count as baselines. Upstream first asks
// the two lens images alone for a stable two-view geometry (a 16°
// triangulation angle, a pose not recoverable when the pair verifies as a
// panorama), then runs the generalized relative pose once per pair of the
// frames' lenses; a rig with little motion between captures never gets
// past the first step, and a search over many lenses takes minutes.
#pragma once

#include "colmap/scene/database_cache.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/sfm/incremental_mapper.h"
#include "colmap/sfm/incremental_mapper_impl.h"
#include "colmap/util/types.h"

#include <optional>

namespace colmap {

// True when the frame of either image has more than one sensor.
bool IsRigFramePair(const DatabaseCache& database_cache,
                    image_t image_id1,
                    image_t image_id2);

// For rig frames, adds every image pair of the two images' frames to
// `tried_pairs`, so that the initial-pair search tries a pair of frames once
// instead of once per pair of their lenses. Nothing for other images.
void MarkFramePairTried(const DatabaseCache& database_cache,
                        image_t image_id1,
                        image_t image_id2,
                        FlatHashSet<image_pair_t>* tried_pairs);

// IncrementalMapperImpl::EstimateInitialTwoViewGeometry for rig frames: the
// motion of the rig between the two images' frames from the matches between
// all their lenses (generalized relative pose, LO-RANSAC, `init_max_error`),
// accepted when at least `init_min_num_inliers` inliers triangulate at an
// angle (lens offsets included) above `init_min_tri_angle`: a 360° rig also
// sees far directions, whose rays barely converge, so upstream's median
// angle of a single camera's pair would refuse a well-determined pair.
// Returned as the pose between the two images. std::nullopt for images of
// one frame, or too few inliers at a wide angle.
std::optional<IncrementalMapperImpl::InitInfo> EstimateInitialRigFramePair(
    const IncrementalMapper::Options& options,
    const DatabaseCache& database_cache,
    image_t image_id1,
    image_t image_id2);

// The minimum triangulation angle [deg] of the points of the initial frames:
// `init_min_tri_angle` (upstream's) for single cameras; for rig frames the
// triangulator's own `min_angle`, so that points seen by neighbouring
// lenses of one frame are kept (the pair was judged on all its inliers).
double InitialTriangulationMinAngle(const IncrementalMapper::Options& options,
                                    double min_angle,
                                    const Reconstruction& reconstruction,
                                    image_t image_id1);

}  // namespace colmap
