// The last few answers of a check of a camera's parameters, kept per thread.
//
// COLMAP asks some questions of a camera many times with the same
// parameters: the incremental mapper calls Camera::HasBogusParams for every
// 2D-3D correspondence of the image it registers, and the category
// predicates (Camera::IsSpherical, ...) for every estimate. Upstream answers
// them with a few comparisons; SPHERA's whole-field models answer with a
// scan of the lens's field (where the projection folds, whether the image
// circle reaches behind the image plane), which is worth computing once per
// parameter set.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

namespace colmap {

// ANSWER of a function of (model id, width, height, parameters). Get returns
// the kept answer for an identical key (parameters compared exactly, so a
// refined camera is asked again) or COMPUTE()'s, kept in place of the
// oldest. Parameter vectors longer than kMaxParams are not kept. Not
// thread-safe: hold one per thread (thread_local).
template <typename Answer, size_t kSize = 4, size_t kMaxParams = 16>
class RecentAnswers {
 public:
  template <typename Compute>
  Answer Get(int model_id,
             size_t width,
             size_t height,
             const double* params,
             size_t num_params,
             Compute&& compute) {
    if (num_params > kMaxParams) {
      return compute();
    }
    for (const Entry& entry : entries_) {
      if (entry.valid && entry.model_id == model_id && entry.width == width &&
          entry.height == height && entry.num_params == num_params &&
          std::equal(params, params + num_params, entry.params.begin())) {
        return entry.answer;
      }
    }
    Entry& entry = entries_[next_];
    next_ = (next_ + 1) % kSize;
    entry.answer = compute();
    entry.model_id = model_id;
    entry.width = width;
    entry.height = height;
    entry.num_params = num_params;
    std::copy(params, params + num_params, entry.params.begin());
    entry.valid = true;
    return entry.answer;
  }

 private:
  struct Entry {
    bool valid = false;
    int model_id = 0;
    size_t width = 0;
    size_t height = 0;
    size_t num_params = 0;
    std::array<double, kMaxParams> params{};
    Answer answer{};
  };
  std::array<Entry, kSize> entries_;
  size_t next_ = 0;
};

}  // namespace colmap
