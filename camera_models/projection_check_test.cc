// The check that a camera's projection is usable over its image.
#include "camera_models/projection_check.h"

#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace sphera {
namespace {

using ::testing::HasSubstr;

// Cameras as real data holds them are accepted: every model's initial
// parameters, and fisheye lenses past 180° whose image circle lies inside
// the frame (pixels outside the circle have no ray, which is allowed).
TEST(ProjectionCheck, AcceptsUsableCameras) {
  for (const int id : {1, 4, 5, 10, 16, 17, 64, 65, 66}) {
    const int width = id == 17 ? 2048 : 1280;
    const int height = id == 17 ? 1024 : 960;
    const std::vector<double> params = InitialParams(id, 400, width, height);
    EXPECT_EQ(ProjectionOverImageError(id, params, width, height), "")
        << "model " << id;
  }
  // A 1600x1600 lens of about 220°: EUCM, DOUBLE_SPHERE, UNIFIED_OMNI.
  EXPECT_EQ(ProjectionOverImageError(16, {480, 480, 800, 800, 0.62, 1.1},
                                     1600, 1600),
            "");
  EXPECT_EQ(ProjectionOverImageError(65, {450, 450, 800, 800, -0.2, 0.6},
                                     1600, 1600),
            "");
  EXPECT_EQ(ProjectionOverImageError(
                64, {900, 900, 800, 800, 1.6, -0.05, 0.01, 1e-4, -1e-4},
                1600, 1600),
            "");
  // Lenses whose field ends where the model's domain ends, before 90° from
  // the axis at the sampled pixels (EUCM alpha 1, beta 100: rays only
  // within 2 px of the centre; alpha 0.8, beta 4 on a small focal length):
  // the model sees no ray beyond, so the image past it has none, as
  // outside a fisheye's circle.
  EXPECT_EQ(ProjectionOverImageError(16, {20, 20, 160, 120, 1, 100}, 320,
                                     240),
            "");
  EXPECT_EQ(ProjectionOverImageError(16, {300, 300, 640, 480, 0.8, 4.0},
                                     1280, 960),
            "");
  // A principal point off the image centre, and one just outside the image.
  EXPECT_EQ(ProjectionOverImageError(1, {500, 500, 300, 200}, 640, 480), "");
  EXPECT_EQ(ProjectionOverImageError(1, {500, 500, -100, 200}, 640, 480), "");
}

// Values each allowed by CheckParams that leave no usable projection.
TEST(ProjectionCheck, RefusesAbsurdValuesNamingWhy) {
  // A distortion coefficient of 1e300: the inverse cannot be computed.
  const std::string huge_k2 = ProjectionOverImageError(
      64, {400, 400, 640, 480, 1.0, 0.0, 1e300, 0, 0}, 1280, 960);
  EXPECT_THAT(huge_k2, HasSubstr("UNIFIED_OMNI"));
  EXPECT_THAT(huge_k2, HasSubstr("1280x960 image"));
  // A barrel distortion that folds inside the image.
  const std::string fold = ProjectionOverImageError(
      4, {300, 300, 640, 480, -0.6, 0, 0, 0}, 1280, 960);
  EXPECT_THAT(fold, HasSubstr("OPENCV"));
  EXPECT_FALSE(fold.empty());
  const std::string omni_fold = ProjectionOverImageError(
      64, {300, 300, 640, 480, 1.0, -0.9, 0, 0, 0}, 1280, 960);
  EXPECT_THAT(omni_fold, HasSubstr("UNIFIED_OMNI"));
  // Pixels that lose their ray before 90° though the model projects rays
  // further out: the message names the angle where the inverse stops.
  EXPECT_THAT(omni_fold, HasSubstr("from the axis"));
  // A principal point a thousand images away.
  EXPECT_THAT(ProjectionOverImageError(1, {500, 500, 1e6, 240}, 640, 480),
              HasSubstr("far outside the 640x480 image"));
  EXPECT_THAT(ProjectionOverImageError(16, {400, 400, 640, -1e7, 0.6, 1.0},
                                       1280, 960),
              HasSubstr("far outside"));
  // A focal length so small that no pixel but the centre has a ray: the
  // model's domain ends 0.0005 px from it.
  EXPECT_THAT(ProjectionOverImageError(16, {1e-3, 1e-3, 640, 480, 0.9, 5.0},
                                       1280, 960),
              HasSubstr("covers less than a pixel"));
}

// Nothing to check without an image size.
TEST(ProjectionCheck, NoImageSizeNoCheck) {
  EXPECT_EQ(ProjectionOverImageError(64, {400, 400, 0, 0, 1, 0, 1e300, 0, 0},
                                     0, 0),
            "");
}

}  // namespace
}  // namespace sphera
