#include "colmap_ext/sfm/initial_pair_search.h"

#include "colmap/util/threading.h"

#include <algorithm>
#include <atomic>
#include <future>
#include <utility>

namespace colmap {
namespace {

// The pairs one seed tries: its second images, in order.
struct SeedPlan {
  image_t seed = kInvalidImageId;
  std::vector<image_t> second;
};

// Marks (SEED, SECOND) tried in TRIED as the search does; false when it
// was already.
bool MarkTried(const InitialPairSearch& search,
               image_t seed,
               image_t second,
               FlatHashSet<image_pair_t>* tried) {
  if (!tried->emplace(ImagePairToPairId(seed, second)).second) {
    return false;
  }
  if (search.mark_tried) {
    search.mark_tried(seed, second, tried);
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
    const FlatHashSet<image_pair_t> tried_before = *tried_pairs;
    std::vector<SeedPlan> plans;
    for (size_t i = begin; i < end; ++i) {
      SeedPlan plan{seeds[i], {}};
      for (const image_t second : search.second_images(seeds[i])) {
        if (MarkTried(search, seeds[i], second, tried_pairs)) {
          plan.second.push_back(second);
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
    // The tried pairs as one thread leaves them: every pair of the seeds
    // before the winner, and the winner's up to its good pair.
    *tried_pairs = tried_before;
    for (size_t k = 0; k <= winner_seed; ++k) {
      const size_t count =
          k < winner_seed ? plans[k].second.size() : winner->first + 1;
      for (size_t j = 0; j < count; ++j) {
        MarkTried(search, plans[k].seed, plans[k].second[j], tried_pairs);
      }
    }
    return std::move(winner->second);
  }
  return std::nullopt;
}

}  // namespace colmap
