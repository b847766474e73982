// A camera of a whole-field model (OPENCV_FISHEYE, THIN_PRISM_FISHEYE, EUCM)
// takes upstream's category exactly when the image circle its frame shows
// lies in front of its image plane, and bundle adjustment then builds
// upstream's own pixel cost for it; with rays past 90° in that circle it
// stays spherical with the angular cost.
#include "colmap_ext/scene/camera_category.h"

#include "colmap/estimators/cost_functions/reprojection_error.h"
#include "colmap/geometry/rigid3.h"
#include "colmap/scene/camera.h"
#include "colmap_ext/estimators/sphere_cost_functions.h"

#include <memory>
#include <string>
#include <typeinfo>
#include <vector>

#include <gtest/gtest.h>

namespace colmap {
namespace {

Camera MakeCamera(const std::string& model,
                  std::vector<double> params,
                  const size_t size) {
  Camera camera;
  camera.camera_id = 1;
  camera.model_id = CameraModelNameToId(model);
  params[2] = size / 2.0;
  params[3] = size / 2.0;
  camera.params = params;
  camera.width = size;
  camera.height = size;
  camera.has_prior_focal_length = true;
  return camera;
}

// Equidistant f = 300: rays at 90° land 471 px from the centre; a 640 px
// square frame shows an image circle of 320 px about it, a 1000 px one of
// 500 px.
const std::vector<double> kEquidistant = {300, 300, 0, 0, 0, 0, 0, 0};
const std::vector<double> kThinPrism = {
    300, 300, 0, 0, 0, 0, 2e-4, -1e-4, 0, 0, 1e-4, 2e-4};
// EUCM: rays at 90° land 1 / (alpha sqrt(beta)) f = 477 px from the centre.
const std::vector<double> kEUCM = {300, 300, 0, 0, 0.6, 1.1};

void ExpectPerspective(const Camera& camera, const bool fisheye) {
  EXPECT_TRUE(camera.IsPerspective());
  EXPECT_FALSE(camera.IsSpherical());
  EXPECT_EQ(camera.IsPerspectiveFisheye(), fisheye);
  EXPECT_EQ(camera.IsPerspectivePinhole(), !fisheye);
}

void ExpectSpherical(const Camera& camera) {
  EXPECT_FALSE(camera.IsPerspective());
  EXPECT_TRUE(camera.IsSpherical());
  EXPECT_FALSE(camera.IsPerspectiveFisheye());
  EXPECT_FALSE(camera.IsPerspectivePinhole());
}

TEST(CameraCategory, WholeFieldModelsTakeUpstreamsCategoryInFront) {
  ExpectPerspective(MakeCamera("OPENCV_FISHEYE", kEquidistant, 640), true);
  ExpectSpherical(MakeCamera("OPENCV_FISHEYE", kEquidistant, 1000));
  ExpectPerspective(MakeCamera("THIN_PRISM_FISHEYE", kThinPrism, 640), true);
  ExpectSpherical(MakeCamera("THIN_PRISM_FISHEYE", kThinPrism, 1000));
  ExpectPerspective(MakeCamera("EUCM", kEUCM, 640), false);
  ExpectSpherical(MakeCamera("EUCM", kEUCM, 1000));
}

// Real lenses: the fits of scripts/fit_real_lenses.py to the refined corners
// of OCamCalib's sample sets (../shared/data/real_cameras/ocamcalib/). The
// 190° fisheye (752 x 480, its circle cropped at the top and bottom, 98° at
// the rim) and the paracatadioptric camera stay spherical in either model;
// the Ladybug lens (41° at its corners) is upstream's camera.
TEST(CameraCategory, RealLensesFallOnTheRightSide) {
  const auto camera = [](const std::string& model,
                         const std::vector<double>& params,
                         const size_t width,
                         const size_t height) {
    Camera c;
    c.model_id = CameraModelNameToId(model);
    c.params = params;
    c.width = width;
    c.height = height;
    c.has_prior_focal_length = true;
    return c;
  };
  ExpectSpherical(camera("OPENCV_FISHEYE",
                         {209.3776, 209.1093, 358.9734, 244.2221, -0.046997,
                          0.013335, -0.016102, 0.003241},
                         752,
                         480));
  ExpectSpherical(camera(
      "EUCM", {208.9695, 208.6981, 358.9119, 244.2251, 0.757601, 0.973323},
      752,
      480));
  ExpectPerspective(camera("OPENCV_FISHEYE",
                           {550.1279, 548.6234, 503.2291, 384.5753, -0.070295,
                            0.094461, -0.328593, 0.346520},
                           1024,
                           768),
                    true);
  ExpectPerspective(camera("EUCM",
                           {550.0430, 548.5562, 503.2243, 384.5174, 0.752360,
                            1.047576},
                           1024,
                           768),
                    false);
  ExpectSpherical(camera(
      "EUCM", {148.6651, 148.8086, 643.6744, 523.1360, 0.529208, 1.009811},
      1280,
      1024));
}

TEST(CameraCategory, OtherCamerasKeepTheirModelsCategory) {
  // The same lens as a camera without an image size, with parameters of the
  // wrong count, and with a focal length the image reader guessed, is the
  // model's: spherical.
  Camera guessed = MakeCamera("OPENCV_FISHEYE", kEquidistant, 640);
  guessed.has_prior_focal_length = false;
  ExpectSpherical(guessed);
  Camera no_size = MakeCamera("OPENCV_FISHEYE", kEquidistant, 640);
  no_size.width = 0;
  no_size.height = 0;
  ExpectSpherical(no_size);
  Camera short_params = MakeCamera("OPENCV_FISHEYE", kEquidistant, 640);
  short_params.params.pop_back();
  ExpectSpherical(short_params);
  // SPHERA's own models have no upstream twin: spherical at any size.
  ExpectSpherical(
      MakeCamera("DOUBLE_SPHERE", {300, 300, 0, 0, -0.1, 0.55}, 200));
  ExpectPerspective(MakeCamera("PINHOLE", {300, 300, 0, 0}, 640), false);
  Camera panorama = Camera::CreateFromModelName(1, "EQUIRECTANGULAR", 0, 2000, 1000);
  panorama.has_prior_focal_length = true;
  ExpectSpherical(panorama);
  EXPECT_EQ(InFrontCameraCategory(MakeCamera("PINHOLE", {300, 300, 0, 0}, 640)),
            UpstreamCategory::kNone);
}

// The residual of the cost that bundle adjustment builds for an observation
// at PIXEL of a point 20° off the axis.
std::unique_ptr<ceres::CostFunction> CostFor(const Camera& camera,
                                             const Eigen::Vector2d& pixel,
                                             Eigen::Vector2d* residual) {
  std::unique_ptr<ceres::CostFunction> cost(
      CreateSphereCameraCostFunction<ReprojErrorCostFunctor>(
          SphereResidualType::ANGULAR, camera, pixel));
  const Eigen::Vector3d point(std::tan(20 * M_PI / 180), 0, 1);
  const Rigid3d cam_from_world;
  const double* parameters[3] = {
      point.data(), cam_from_world.params.data(), camera.params.data()};
  EXPECT_TRUE(cost->Evaluate(parameters, residual->data(), nullptr));
  return cost;
}

TEST(CameraCategory, InFrontCameraGetsUpstreamsPixelCost) {
  const Eigen::Vector2d offset(1.5, -2.0);
  for (const size_t size : {640, 1000}) {
    const Camera camera = MakeCamera("OPENCV_FISHEYE", kEquidistant, size);
    const Eigen::Vector2d projection(size / 2.0 + 300 * 20 * M_PI / 180,
                                     size / 2.0);
    Eigen::Vector2d residual;
    const auto cost = CostFor(camera, projection + offset, &residual);
    if (size == 640) {
      EXPECT_EQ(typeid(*cost),
                typeid(AnalyticalReprojErrorCostFunction<
                       OpenCVFisheyeCameraModel>));
      EXPECT_NEAR((residual + offset).norm(), 0, 1e-9);
    } else {
      EXPECT_EQ(typeid(*cost),
                typeid(AngularReprojErrorCostFunction<
                       SphereOpenCVFisheyeCameraModel>));
      // An angle in pixel equivalents: close to, but not, the pixel offset.
      EXPECT_GT((residual + offset).norm(), 1e-6);
      EXPECT_NEAR(residual.norm(), offset.norm(), 0.1);
    }
  }
}

}  // namespace
}  // namespace colmap
