#include "colmap_ext/scene/model_file_errors.h"

#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

namespace colmap {
namespace {

TEST(ModelFileErrors, TrackOfPairs) {
  Track track;
  std::istringstream good(" 1 0 2 5");
  ReadTrackText(good, 7, &track);
  ASSERT_EQ(track.Length(), 2);
  EXPECT_EQ(track.Element(1).image_id, 2);
  EXPECT_EQ(track.Element(1).point2D_idx, 5);

  std::istringstream odd(" 1 0 2");
  EXPECT_THROW(ReadTrackText(odd, 7, &track), std::runtime_error);
  std::istringstream text(" 1 0 x 3");
  EXPECT_THROW(ReadTrackText(text, 7, &track), std::runtime_error);
}

TEST(ModelFileErrors, PoseAndFrameOfAnImage) {
  Rigid3d cam_from_world;
  EXPECT_NO_THROW(CheckFinitePose(1, cam_from_world));
  cam_from_world.translation().x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(CheckFinitePose(1, cam_from_world), std::runtime_error);

  Frame frame;
  const std::map<image_t, Frame*> image_to_frame = {{3, &frame}};
  EXPECT_EQ(FrameOfImage(image_to_frame, 3), &frame);
  EXPECT_THROW(FrameOfImage(image_to_frame, 4), std::runtime_error);
}

}  // namespace
}  // namespace colmap
