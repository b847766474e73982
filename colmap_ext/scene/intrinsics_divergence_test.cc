#include "colmap_ext/scene/intrinsics_divergence.h"

#include <limits>

#include <gtest/gtest.h>

namespace colmap {
namespace {

Camera MakeCamera(const std::string& model, std::vector<double> params) {
  Camera camera = Camera::CreateFromModelName(1, model, 1, 1024, 1024);
  camera.params = std::move(params);
  return camera;
}

TEST(IntrinsicsDivergence, PlausibleRefinementsPass) {
  const Camera prior = MakeCamera("EUCM", {280, 280, 512, 512, 0.6, 1.0});
  // 20% off either way, slightly non-square, shape parameters moved.
  EXPECT_EQ(IntrinsicsDivergence(
                prior, MakeCamera("EUCM", {236, 236.5, 512, 512, 0.62, 1.05})),
            "");
  EXPECT_EQ(IntrinsicsDivergence(
                prior, MakeCamera("EUCM", {336, 335, 510, 515, 0.58, 0.95})),
            "");
  const Camera pinhole = MakeCamera("PINHOLE", {500, 500, 512, 512});
  EXPECT_EQ(IntrinsicsDivergence(pinhole,
                                 MakeCamera("PINHOLE", {700, 690, 512, 512})),
            "");
  const Camera panorama = MakeCamera("EQUIRECTANGULAR", {1024, 1024});
  EXPECT_EQ(IntrinsicsDivergence(panorama, panorama), "");
}

TEST(IntrinsicsDivergence, RunawaysAreNamed) {
  const Camera prior = MakeCamera("EUCM", {280, 280, 512, 512, 0.6, 1.0});
  // The real 197° lens of the issue: fx = 97,205, fy = 29.
  std::string why = IntrinsicsDivergence(
      prior, MakeCamera("EUCM", {97205, 29, 512, 512, 0.6, 1.0}));
  EXPECT_NE(why.find("focal length went from 280"), std::string::npos) << why;
  EXPECT_NE(why.find("fy 29"), std::string::npos) << why;
  // Within the focal ratio but no longer square.
  why = IntrinsicsDivergence(prior,
                             MakeCamera("EUCM", {330, 250, 512, 512, 0.6, 1.0}));
  EXPECT_NE(why.find("fx / fy"), std::string::npos) << why;
  // A camera whose prior is not square may stay so.
  const Camera oblong = MakeCamera("EUCM", {330, 250, 512, 512, 0.6, 1.0});
  EXPECT_EQ(IntrinsicsDivergence(
                oblong, MakeCamera("EUCM", {331, 251, 512, 512, 0.6, 1.0})),
            "");
  // Focal length 5x off.
  why = IntrinsicsDivergence(
      prior, MakeCamera("EUCM", {1400, 1400, 512, 512, 0.6, 1.0}));
  EXPECT_NE(why.find("focal length"), std::string::npos) << why;
  // Outside the model's valid range (EUCM: alpha in [0, 1]).
  why = IntrinsicsDivergence(prior,
                             MakeCamera("EUCM", {280, 280, 512, 512, 1.7, 1.0}));
  EXPECT_NE(why.find("valid range of EUCM"), std::string::npos) << why;
  // Not finite.
  why = IntrinsicsDivergence(
      prior,
      MakeCamera("EUCM", {std::numeric_limits<double>::quiet_NaN(), 280, 512,
                          512, 0.6, 1.0}));
  EXPECT_NE(why.find("not finite"), std::string::npos) << why;
  // Principal point outside the image.
  why = IntrinsicsDivergence(
      MakeCamera("PINHOLE", {500, 500, 512, 512}),
      MakeCamera("PINHOLE", {500, 500, -40, 512}));
  EXPECT_FALSE(why.empty());
}

TEST(DivergedCameraHold, SetsBackHoldsAndNamesARunaway) {
  const Camera prior = MakeCamera("EUCM", {280, 280, 512, 512, 0.6, 1.0});
  DatabaseCache database_cache;
  database_cache.AddCamera(prior);
  Camera unknown = prior;
  unknown.camera_id = 2;
  Reconstruction reconstruction;
  reconstruction.AddCamera(prior);
  reconstruction.AddCamera(unknown);

  DivergedCameraHold hold;
  hold.Remember(reconstruction);
  reconstruction.Camera(1).params[0] = 97205;
  reconstruction.Camera(2).params[0] = 97205;
  hold.HoldDiverged(database_cache, IntrinsicsDivergenceOptions(),
                    &reconstruction);
  // Held whatever the number of frames; a camera without a prior is not
  // judged.
  const FlatHashMap<camera_t, size_t> num_images = {{1, 10}, {2, 10}};
  IntrinsicsDivergenceOptions options;
  options.min_rig_frames = 0;
  EXPECT_EQ(hold.ConstantIntrinsics(reconstruction, num_images, options),
            std::unordered_set<camera_t>{1});
  EXPECT_EQ(reconstruction.Camera(1).params, prior.params);
  ASSERT_EQ(hold.Held().size(), 1);
  EXPECT_EQ(hold.Held()[0].camera.params, prior.params);
  EXPECT_NE(hold.Held()[0].reason.find("focal length"), std::string::npos);

  // A held camera is not set back again.
  hold.Remember(reconstruction);
  reconstruction.Camera(1).params[0] = 5000;
  hold.HoldDiverged(database_cache, IntrinsicsDivergenceOptions(),
                    &reconstruction);
  EXPECT_EQ(reconstruction.Camera(1).params[0], 5000);
  EXPECT_EQ(hold.Held().size(), 1);
}

TEST(DivergedCameraHold, RigLensesAreReleasedFromTheirNthFrame) {
  Reconstruction reconstruction;
  for (camera_t camera_id = 1; camera_id <= 4; ++camera_id) {
    Camera camera = MakeCamera("EUCM", {280, 280, 512, 512, 0.6, 1.0});
    camera.camera_id = camera_id;
    reconstruction.AddCamera(camera);
  }
  // Cameras 1 and 2 are the lenses of one rig; 3 and 4 are cameras alone.
  Rig rig;
  rig.SetRigId(1);
  rig.AddRefSensor(sensor_t(SensorType::CAMERA, 1));
  rig.AddSensor(sensor_t(SensorType::CAMERA, 2), Rigid3d());
  reconstruction.AddRig(rig);
  for (camera_t camera_id = 3; camera_id <= 4; ++camera_id) {
    Rig single;
    single.SetRigId(camera_id);
    single.AddRefSensor(sensor_t(SensorType::CAMERA, camera_id));
    reconstruction.AddRig(single);
  }

  const DivergedCameraHold hold;
  // Lens 1 in two registered frames, lens 2 in three; camera 3 in one
  // image, camera 4 in none: cameras alone are never kept constant here.
  const FlatHashMap<camera_t, size_t> num_images = {{1, 2}, {2, 3}, {3, 1}};
  const auto constant = [&](const FlatHashMap<camera_t, size_t>& num_images,
                            int min_rig_frames) {
    IntrinsicsDivergenceOptions options;
    options.min_rig_frames = min_rig_frames;
    return hold.ConstantIntrinsics(reconstruction, num_images, options);
  };
  EXPECT_EQ(constant(num_images, 3), std::unordered_set<camera_t>{1});
  EXPECT_EQ(constant(num_images, 4), (std::unordered_set<camera_t>{1, 2}));
  // A lens not registered yet counts as none; 0 releases every lens.
  EXPECT_EQ(constant({{1, 5}}, 1), std::unordered_set<camera_t>{2});
  EXPECT_TRUE(constant({}, 0).empty());
}

}  // namespace
}  // namespace colmap
