#include "colmap_ext/scene/unused_cameras.h"

#include "colmap/scene/database.h"

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace colmap {
namespace {

TEST(UnusedCameras, CamerasWithoutImagesAreRemoved) {
  const std::filesystem::path path =
      std::filesystem::path(testing::TempDir()) / "unused_cameras.db";
  std::filesystem::remove(path);
  EXPECT_EQ(RemoveUnusedCameras(path, -1), 0);  // no database yet
  camera_t used_id = 0;
  camera_t kept_id = 0;
  {
    auto database = Database::Open(path);
    const Camera camera =
        Camera::CreateFromModelName(kInvalidCameraId, "PINHOLE", 100, 64, 48);
    used_id = database->WriteCamera(camera);
    database->WriteCamera(camera);
    kept_id = database->WriteCamera(camera);
    Image image;
    image.SetName("a.jpg");
    image.SetCameraId(used_id);
    database->WriteImage(image);
  }
  EXPECT_EQ(RemoveUnusedCameras(path, kept_id), 1);
  auto database = Database::Open(path);
  EXPECT_EQ(database->NumCameras(), 2);
  EXPECT_TRUE(database->ExistsCamera(used_id));
  EXPECT_TRUE(database->ExistsCamera(kept_id));
}

}  // namespace
}  // namespace colmap
