#include "camera_models/recent_answers.h"

#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace sphera {
namespace {

// How many times a check was computed behind RecentAnswers, keyed on a
// camera's (model id, width) and its parameters.
struct CountedCheck {
  int calls = 0;
  RecentAnswers<int, 2, 5> answers;
  int Ask(int model_id, int width, const std::vector<double>& params) {
    const double camera[2] = {static_cast<double>(model_id),
                              static_cast<double>(width)};
    return answers.Get(camera, 2, params.data(), params.size(),
                       [&] { return ++calls; });
  }
};

TEST(RecentAnswers, SameKeyIsComputedOnce) {
  CountedCheck check;
  EXPECT_EQ(check.Ask(5, 100, {1, 2, 3}), 1);
  EXPECT_EQ(check.Ask(5, 100, {1, 2, 3}), 1);
  EXPECT_EQ(check.calls, 1);
}

TEST(RecentAnswers, AnyPartOfTheKeyChangedIsAskedAgain) {
  CountedCheck check;
  check.Ask(5, 100, {1, 2, 3});
  EXPECT_EQ(check.Ask(5, 100, {1, 2, 3.0000000001}), 2);  // a refined lens
  EXPECT_EQ(check.Ask(10, 100, {1, 2, 3}), 3);            // another model
  EXPECT_EQ(check.Ask(5, 101, {1, 2, 3}), 4);             // another frame
  EXPECT_EQ(check.Ask(5, 100, {1, 2}), 5);                // fewer params
  EXPECT_EQ(check.calls, 5);
}

TEST(RecentAnswers, KeepsTheLastFewAndForgetsTheOldest) {
  CountedCheck check;  // two entries
  check.Ask(5, 100, {1});
  check.Ask(5, 100, {2});
  EXPECT_EQ(check.Ask(5, 100, {1}), 1);
  EXPECT_EQ(check.Ask(5, 100, {2}), 2);
  check.Ask(5, 100, {3});  // replaces {1}
  EXPECT_EQ(check.Ask(5, 100, {2}), 2);
  EXPECT_EQ(check.Ask(5, 100, {1}), 4);
  EXPECT_EQ(check.calls, 4);
}

TEST(RecentAnswers, NaNKeysAreAlwaysComputed) {
  CountedCheck check;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  check.Ask(5, 100, {nan});
  check.Ask(5, 100, {nan});
  EXPECT_EQ(check.calls, 2);
}

TEST(RecentAnswers, LongKeysAreNotKept) {
  CountedCheck check;  // at most 5 numbers: 2 of the camera, 3 parameters
  check.Ask(5, 100, {1, 2, 3, 4});
  check.Ask(5, 100, {1, 2, 3, 4});
  EXPECT_EQ(check.calls, 2);
  check.Ask(5, 100, {1, 2, 3});
  check.Ask(5, 100, {1, 2, 3});
  EXPECT_EQ(check.calls, 3);
}

TEST(RecentAnswers, AnEmptyCacheMatchesNoKey) {
  RecentAnswers<int, 2, 3> answers;
  int calls = 0;
  EXPECT_EQ(answers.Get(nullptr, 0, [&] { return ++calls + 10; }), 11);
  EXPECT_EQ(answers.Get(nullptr, 0, [&] { return ++calls + 10; }), 11);
  EXPECT_EQ(calls, 1);
}

}  // namespace
}  // namespace sphera
