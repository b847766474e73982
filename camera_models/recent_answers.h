// The last few answers of a function of a short list of numbers, kept per
// thread.
//
// Some questions are asked many times with the same numbers: the field of
// view of a Kannala-Brandt lens for every pixel the renderer draws and every
// residual bundle adjustment evaluates, and COLMAP's checks of a camera's
// parameters (Camera::HasBogusParams for every 2D-3D correspondence of an
// image being registered, the category predicates for every estimate).
// Upstream answers those checks with a few comparisons; the whole-field
// models answer with a scan of the lens's field (where the projection folds,
// whether the image circle reaches behind the image plane), which is worth
// computing once per set of numbers.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

namespace sphera {

// ANSWER of a function of a key of at most kMaxKey numbers, given in two
// parts (e.g. a model id and image size, then the parameters). Get returns
// the kept answer for an identical key (compared exactly, so a refined lens
// is asked again; NaN never equals itself, so a key with NaN is always
// computed) or COMPUTE()'s, kept in place of the oldest. Longer keys are
// computed and not kept. Not thread-safe: hold one per thread (thread_local).
template <typename Answer, size_t kSize = 4, size_t kMaxKey = 20>
class RecentAnswers {
 public:
  template <typename Compute>
  Answer Get(const double* head,
             size_t head_size,
             const double* tail,
             size_t tail_size,
             Compute&& compute) {
    if (head_size + tail_size > kMaxKey) {
      return compute();
    }
    for (const Entry& entry : entries_) {
      if (entry.head_size == head_size && entry.tail_size == tail_size &&
          std::equal(head, head + head_size, entry.key.begin()) &&
          std::equal(tail, tail + tail_size, entry.key.begin() + head_size)) {
        return entry.answer;
      }
    }
    Entry& entry = entries_[next_];
    next_ = (next_ + 1) % kSize;
    entry.answer = compute();
    entry.head_size = head_size;
    entry.tail_size = tail_size;
    std::copy(head, head + head_size, entry.key.begin());
    std::copy(tail, tail + tail_size, entry.key.begin() + head_size);
    return entry.answer;
  }

  template <typename Compute>
  Answer Get(const double* key, size_t key_size, Compute&& compute) {
    return Get(key, key_size, nullptr, 0, static_cast<Compute&&>(compute));
  }

 private:
  struct Entry {
    // An empty entry matches no key: its sizes are out of range.
    size_t head_size = kMaxKey + 1;
    size_t tail_size = 0;
    std::array<double, kMaxKey> key{};
    Answer answer{};
  };
  std::array<Entry, kSize> entries_;
  size_t next_ = 0;
};

}  // namespace sphera
