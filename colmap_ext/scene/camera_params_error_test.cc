// The camera check: SPHERA's models (Kannala-Brandt and OCAM included) by
// their projection over the image, upstream's by their values.
#include "colmap_ext/scene/camera_params_error.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace colmap {
namespace {

using ::testing::HasSubstr;

Camera MakeCamera(const std::string& model, std::vector<double> params,
                  size_t width, size_t height) {
  Camera camera;
  camera.camera_id = 1;
  camera.model_id = CameraModelNameToId(model);
  camera.width = width;
  camera.height = height;
  camera.params = std::move(params);
  return camera;
}

TEST(CameraParamsError, AcceptsCamerasOfRealLenses) {
  EXPECT_EQ(CameraParamsError(MakeCamera("PINHOLE", {500, 500, 320, 240},
                                         640, 480)),
            "");
  // A principal point off the image, within one image size of it (a crop).
  EXPECT_EQ(CameraParamsError(MakeCamera("SIMPLE_RADIAL", {500, -300, 240, 0},
                                         640, 480)),
            "");
  EXPECT_EQ(CameraParamsError(MakeCamera("EQUIRECTANGULAR", {640, 320},
                                         640, 320)),
            "");
  EXPECT_EQ(CameraParamsError(MakeCamera(
                "DOUBLE_SPHERE", {450, 450, 800, 800, -0.2, 0.6}, 1600, 1600)),
            "");
  // EUCM whose field ends 2 px from the centre, where the model's domain
  // ends: a useless lens, yet a valid camera.
  EXPECT_EQ(CameraParamsError(MakeCamera("EUCM", {20, 20, 160, 120, 1, 100},
                                         320, 240)),
            "");
  // A Kannala-Brandt lens of 200 degrees, and an OCamCalib camera.
  EXPECT_EQ(CameraParamsError(MakeCamera(
                "OPENCV_FISHEYE",
                {142, 142, 256, 256, 0.01, -0.002, 0, 0}, 512, 512)),
            "");
  EXPECT_EQ(CameraParamsError(MakeCamera(
                "OCAM", {500, 400, 1, 0, 0, -300, 1.25e-3, -6e-7, 0}, 1000,
                800)),
            "");
}

TEST(CameraParamsError, RefusesValuesThatLeaveNoLens) {
  // Each value allowed, no projection that can be inverted over the image.
  EXPECT_THAT(CameraParamsError(MakeCamera(
                  "UNIFIED_OMNI", {200, 200, 160, 120, 1, 0, 1e300, 0, 0},
                  320, 240)),
              HasSubstr("UNIFIED_OMNI"));
  // Upstream's models: a principal point a thousand images away.
  EXPECT_THAT(CameraParamsError(MakeCamera("PINHOLE", {500, 500, 1e6, 240},
                                           640, 480)),
              HasSubstr("principal point (1e+06, 240) lies far outside the "
                        "640x480 image"));
  EXPECT_THAT(CameraParamsError(MakeCamera(
                  "OPENCV", {500, 500, 320, -2000, 0, 0, 0, 0}, 640, 480)),
              HasSubstr("OPENCV principal point"));
  EXPECT_THAT(CameraParamsError(MakeCamera("PINHOLE", {0, 500, 320, 240},
                                           640, 480)),
              HasSubstr("focal length"));
  // Kannala-Brandt whose polynomial turns back 114 px from the centre of
  // a 512x512 image: SPHERA's check of its fold, not upstream's values.
  EXPECT_THAT(CameraParamsError(MakeCamera(
                  "OPENCV_FISHEYE", {142, 142, 256, 256, 0, -0.2, 0, 0}, 512,
                  512)),
              HasSubstr("OPENCV_FISHEYE"));
}

}  // namespace
}  // namespace colmap
