#include "colmap_ext/sfm/initial_pair_search.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <set>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace colmap {
namespace {

constexpr image_t kNumImages = 10;

// Images 1..10 in frames of two (1-2, 3-4, ...); each seed pairs with
// every other image, nearest id first; GOOD pairs are good (either order).
// The seeds' estimates take SLOW_MS each for the first seed and none for the
// others, so that a later seed finishes first.
InitialPairSearch MakeSearch(const std::set<image_pair_t>& good,
                             int slow_ms,
                             std::atomic<int>* num_estimates) {
  InitialPairSearch search;
  search.second_images = [](image_t seed) {
    std::vector<image_t> second;
    for (image_t id = 1; id <= kNumImages; ++id) {
      if (id != seed) second.push_back(id);
    }
    std::stable_sort(second.begin(), second.end(), [seed](image_t a,
                                                          image_t b) {
      return std::abs(static_cast<int>(a) - static_cast<int>(seed)) <
             std::abs(static_cast<int>(b) - static_cast<int>(seed));
    });
    return second;
  };
  search.mark_tried = [](image_t id1, image_t id2,
                         FlatHashSet<image_pair_t>* tried) {
    const image_t frame1 = (id1 - 1) / 2;
    const image_t frame2 = (id2 - 1) / 2;
    for (image_t a = 2 * frame1 + 1; a <= 2 * frame1 + 2; ++a) {
      for (image_t b = 2 * frame2 + 1; b <= 2 * frame2 + 2; ++b) {
        if (a != b) tried->insert(ImagePairToPairId(a, b));
      }
    }
  };
  search.estimate = [good, slow_ms, num_estimates](image_t id1, image_t id2)
      -> std::optional<IncrementalMapperImpl::InitInfo> {
    ++*num_estimates;
    if (slow_ms > 0 && id1 == 1) {
      std::this_thread::sleep_for(std::chrono::milliseconds(slow_ms));
    }
    if (!good.count(ImagePairToPairId(id1, id2))) {
      return std::nullopt;
    }
    IncrementalMapperImpl::InitInfo info;
    info.image_id1 = id1;
    info.image_id2 = id2;
    return info;
  };
  return search;
}

std::vector<image_t> Seeds() {
  std::vector<image_t> seeds;
  for (image_t id = 1; id <= kNumImages; ++id) seeds.push_back(id);
  return seeds;
}

TEST(InitialPairSearch, ManyThreadsGiveWhatOneThreadGives) {
  // Seed 1's good pair is the last it tries, (1, 9) (its frame pairs
  // settle (1, 4), (1, 6), (1, 8), (1, 10)); seed 3 finds (3, 4) at once.
  // With one thread seed 1 wins.
  const std::set<image_pair_t> good = {ImagePairToPairId(1, 9),
                                       ImagePairToPairId(3, 4),
                                       ImagePairToPairId(7, 9)};
  std::atomic<int> num_estimates(0);
  FlatHashSet<image_pair_t> tried_one = {ImagePairToPairId(5, 6)};
  const auto one = FindInitialPairInOrder(
      MakeSearch(good, 0, &num_estimates), Seeds(), 1, &tried_one);
  ASSERT_TRUE(one.has_value());
  EXPECT_EQ(one->image_id1, 1);
  EXPECT_EQ(one->image_id2, 9);
  for (int run = 0; run < 5; ++run) {
    FlatHashSet<image_pair_t> tried = {ImagePairToPairId(5, 6)};
    const auto many = FindInitialPairInOrder(
        MakeSearch(good, 3, &num_estimates), Seeds(), 4, &tried);
    ASSERT_TRUE(many.has_value());
    EXPECT_EQ(many->image_id1, one->image_id1);
    EXPECT_EQ(many->image_id2, one->image_id2);
    // The tried pairs as one thread leaves them: not those of seed 3's
    // pairs, which one thread never reached.
    EXPECT_EQ(std::set<image_pair_t>(tried.begin(), tried.end()),
              std::set<image_pair_t>(tried_one.begin(), tried_one.end()));
  }
}

TEST(InitialPairSearch, PairsTriedBeforeAreSkippedAndNoneGoodIsNothing) {
  // (1, 10) is good but was tried by an earlier search: seeds 1 and 2 find
  // nothing ((2, 3) and (2, 4) settled with seed 1's frame pair), seed 3
  // tries (3, 4).
  const std::set<image_pair_t> good = {ImagePairToPairId(1, 10),
                                       ImagePairToPairId(3, 4)};
  for (const int threads : {1, 3}) {
    std::atomic<int> num_estimates(0);
    FlatHashSet<image_pair_t> tried = {ImagePairToPairId(1, 10)};
    const auto found = FindInitialPairInOrder(
        MakeSearch(good, 0, &num_estimates), Seeds(), threads, &tried);
    ASSERT_TRUE(found.has_value()) << threads;
    EXPECT_EQ(found->image_id1, 3) << threads;
    EXPECT_EQ(found->image_id2, 4) << threads;
  }
  std::atomic<int> num_estimates(0);
  FlatHashSet<image_pair_t> tried;
  const auto none = FindInitialPairInOrder(
      MakeSearch({}, 0, &num_estimates), Seeds(), 4, &tried);
  EXPECT_FALSE(none.has_value());
  // Every pair tried or settled, each frame pair estimated once: the 10
  // pairs of the 5 frames and the 5 pairs inside them.
  EXPECT_EQ(tried.size(), kNumImages * (kNumImages - 1) / 2);
  EXPECT_EQ(num_estimates.load(), 15);
}

}  // namespace
}  // namespace colmap
