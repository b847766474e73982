#include "colmap_ext/controllers/image_errors.h"

#include <gtest/gtest.h>

namespace colmap {
namespace {

TEST(ImageErrors, TooSmallImages) {
  EXPECT_EQ(TooSmallImageError(16, 16), "");
  EXPECT_EQ(TooSmallImageError(15, 480),
            "15x480 pixels: too small to extract features from");
}

TEST(ImageErrors, FileExtensions) {
  EXPECT_TRUE(HasImageFileExtension("a/B.JPG"));
  EXPECT_FALSE(HasImageFileExtension("README"));
  EXPECT_FALSE(HasImageFileExtension("a.d/README"));
}

}  // namespace
}  // namespace colmap
