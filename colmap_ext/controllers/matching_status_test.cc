#include "colmap_ext/controllers/matching_status.h"

#include "colmap_ext/scene/database_check.h"

#include <filesystem>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace colmap {
namespace {

std::filesystem::path NewDatabasePath(const std::string& name) {
  const std::filesystem::path path =
      std::filesystem::path(testing::TempDir()) / name;
  std::filesystem::remove(path);
  return path;
}

TEST(MatchingStatus, NothingToMatchIsAnError) {
  const std::filesystem::path path = NewDatabasePath("nothing_to_match.db");
  Database::Open(path);
  try {
    OpenDatabaseToMatch(path);
    ADD_FAILURE() << "a database without images has nothing to match";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("no images to match"),
              std::string::npos);
  }
  EXPECT_NE(NoVerifiedPairError(path, 15).find("holds 0 image(s)"),
            std::string::npos);
  EXPECT_TRUE(HoldsDatabase(path));
  EXPECT_FALSE(HoldsDatabase(NewDatabasePath("none.db")));
}

TEST(DatabaseCheck, MatchOfMissingKeypointNamesImagesAndKeypoint) {
  EXPECT_EQ(MatchOfMissingKeypointError(1, 2, 2, 700, 512),
            "the verified matches of images 1 and 2 refer to keypoint 700 of "
            "image 2, which has 512 keypoints: the database's matches do not "
            "belong to its keypoints (match the images again)");
}

}  // namespace
}  // namespace colmap
