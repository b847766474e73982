#include "colmap_ext/sfm/initial_pair_search.h"

#include "colmap/util/threading.h"

#include <algorithm>
#include <atomic>
#include <future>
#include <utility>

namespace colmap {
namespace {

// The pairs one seed tries: its second images, in order, and for each the
// end of what trying it added to the tried set (an index into the batch's
// list of added pair ids).
struct SeedPlan {
  image_t seed = kInvalidImageId;
  std::vector<image_t> second;
  std::vector<size_t> added_end;
};

// Marks (SEED, SECOND) tried in TRIED as the search does, appending the ids
// it adds to ADDED; false when the pair was tried already.
bool MarkTried(const InitialPairSearch& search,
               image_t seed,
               image_t second,
               FlatHashSet<image_pair_t>* tried,
               std::vector<image_pair_t>* added) {
  const image_pair_t pair_id = ImagePairToPairId(seed, second);
  if (tried->count(pair_id)) {
    return false;
  }
  FlatHashSet<image_pair_t> marks = {pair_id};
  if (search.mark_tried) {
    search.mark_tried(seed, second, &marks);
  }
  for (const image_pair_t id : marks) {
    if (tried->insert(id).second) {
      added->push_back(id);
    }
  }
  return true;
}

}  // namespace

std::optional<IncrementalMapperImpl::InitInfo> FindInitialPairInOrder(
    const InitialPairSearch& search,
    const std::vector<image_t>& seeds,
    const int num_threads,
    FlatHashSet<image_pair_t>* tried_pairs) {
  const size_t batch_size =
      static_cast<size_t>(std::max(1, GetEffectiveNumThreads(num_threads)));
  ThreadPool thread_pool(static_cast<int>(batch_size));
  for (size_t begin = 0; begin < seeds.size(); begin += batch_size) {
    const size_t end = std::min(seeds.size(), begin + batch_size);
    // The pairs of each seed of the batch, planned as one thread tries
    // them, every seed before it having failed.
    std::vector<image_pair_t> added;
    std::vector<SeedPlan> plans;
    for (size_t i = begin; i < end; ++i) {
      SeedPlan plan{seeds[i], {}, {}};
      for (const image_t second : search.second_images(seeds[i])) {
        if (MarkTried(search, seeds[i], second, tried_pairs, &added)) {
          plan.second.push_back(second);
          plan.added_end.push_back(added.size());
        }
      }
      plans.push_back(std::move(plan));
    }

    // The estimates; a task stops once an earlier seed has succeeded.
    std::atomic<size_t> first_success(plans.size());
    using Found = std::pair<size_t, IncrementalMapperImpl::InitInfo>;
    std::vector<std::shared_future<std::optional<Found>>> results;
    for (size_t k = 0; k < plans.size(); ++k) {
      results.push_back(thread_pool.AddTask(
          [&search, &plans, &first_success, k]() -> std::optional<Found> {
            const SeedPlan& plan = plans[k];
            for (size_t j = 0; j < plan.second.size(); ++j) {
              if (first_success.load() < k) {
                return std::nullopt;
              }
              std::optional<IncrementalMapperImpl::InitInfo> info =
                  search.estimate(plan.seed, plan.second[j]);
              if (info.has_value()) {
                size_t current = first_success.load();
                while (k < current &&
                       !first_success.compare_exchange_weak(current, k)) {
                }
                return Found(j, std::move(*info));
              }
            }
            return std::nullopt;
          }));
    }
    std::optional<Found> winner;
    size_t winner_seed = 0;
    for (size_t k = 0; k < plans.size() && !winner; ++k) {
      winner = results[k].get();
      winner_seed = k;
    }
    thread_pool.Wait();
    if (!winner) {
      continue;  // every pair of the batch tried, as one thread would
    }
    // The tried pairs as one thread leaves them: those of the seeds before
    // the winner and of the winner up to its good pair.
    const size_t keep = plans[winner_seed].added_end[winner->first];
    for (size_t i = keep; i < added.size(); ++i) {
      tried_pairs->erase(added[i]);
    }
    return std::move(winner->second);
  }
  return std::nullopt;
}

}  // namespace colmap
