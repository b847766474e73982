// The incremental mapper's search for an initial image pair on several
// threads, with the result one thread gives.
//
// Upstream runs one task per seed image (the first image of a pair) on a
// thread pool and returns the first seed, in order, whose task found a good
// pair, which it calls deterministic. It is not: a task that finds a pair
// stops every task still running, earlier seeds' included, and the tasks
// share the set of pairs already tried, so which pairs an earlier seed gets
// to try depends on the threads' timing. On a capture with few good pairs
// (a mostly turning 360° camera) two runs on one database then start from
// different pairs and end in different models.
//
// Here the pairs each seed tries are planned first, seed by seed, as one
// thread would try them (a pair, or with MarkFramePairTried its rig frame
// pair, tried by an earlier seed or an earlier search is skipped), for as
// many seeds at a time as there are threads; their estimates then run in
// parallel, a seed's task stopping only when an earlier seed has succeeded;
// the first seed in order with a good pair wins, and the set of tried pairs
// ends as one thread leaves it.
#pragma once

#include "colmap/sfm/incremental_mapper_impl.h"
#include "colmap/util/types.h"

#include <functional>
#include <optional>
#include <vector>

namespace colmap {

struct InitialPairSearch {
  // The images SEED pairs with, best first (FindSecondInitialImage).
  std::function<std::vector<image_t>(image_t seed)> second_images;
  // Adds to TRIED the pairs that trying (IMAGE_ID1, IMAGE_ID2) also settles
  // (MarkFramePairTried: every lens pair of two rig frames); may be empty.
  std::function<void(image_t image_id1,
                     image_t image_id2,
                     FlatHashSet<image_pair_t>* tried)>
      mark_tried;
  // The two-view geometry of the pair, or nothing when it is not a good
  // initial pair (EstimateInitialTwoViewGeometry). Called concurrently.
  std::function<std::optional<IncrementalMapperImpl::InitInfo>(
      image_t image_id1, image_t image_id2)>
      estimate;
};

// The first good pair over SEEDS in order, searched on NUM_THREADS threads
// (COLMAP's convention: <= 0 for all cores); TRIED_PAIRS, the pairs tried
// by earlier searches, gains those this search tried, as with one thread.
std::optional<IncrementalMapperImpl::InitInfo> FindInitialPairInOrder(
    const InitialPairSearch& search,
    const std::vector<image_t>& seeds,
    int num_threads,
    FlatHashSet<image_pair_t>* tried_pairs);

}  // namespace colmap
