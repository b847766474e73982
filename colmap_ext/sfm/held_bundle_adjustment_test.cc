#include "colmap_ext/sfm/held_bundle_adjustment.h"

#include "colmap/scene/database_sqlite.h"
#include "colmap/scene/synthetic.h"

#include <gtest/gtest.h>

namespace colmap {
namespace {

struct Scene {
  Reconstruction reconstruction;
  std::shared_ptr<DatabaseCache> cache;
};

// `num_rigs` rigs of `num_cameras` cameras each, exact observations, every
// focal length 3% off the truth in the reconstruction (not in the
// database, whose cameras are the priors).
Scene MakeScene(int num_rigs, int num_cameras) {
  SyntheticDatasetOptions options;
  options.num_rigs = num_rigs;
  options.num_cameras_per_rig = num_cameras;
  options.num_frames_per_rig = 4;
  options.num_points3D = 200;
  Scene scene;
  std::shared_ptr<Database> database =
      Database::Open(kInMemorySqliteDatabasePath);
  SynthesizeDataset(options, &scene.reconstruction, database.get());
  scene.cache = DatabaseCache::Create(*database, DatabaseCache::Options());
  for (const auto& [camera_id, camera] : scene.reconstruction.Cameras()) {
    Camera& off = scene.reconstruction.Camera(camera_id);
    off.params[0] *= 1.03;
  }
  return scene;
}

std::map<camera_t, std::vector<double>> Params(const Reconstruction& r) {
  std::map<camera_t, std::vector<double>> params;
  for (const auto& [camera_id, camera] : r.Cameras()) {
    params[camera_id] = camera.params;
  }
  return params;
}

// One adjustment that refines the intrinsics, unless held.
bool Adjust(Scene& scene, bool hold_rig_lenses, DivergedCameraHold& hold) {
  BundleAdjustmentOptions options;
  options.refine_focal_length = true;
  options.refine_extra_params = true;
  options.print_summary = false;
  return RunHeldBundleAdjustment(options,
                                 *scene.cache,
                                 IntrinsicsDivergenceOptions(),
                                 hold_rig_lenses,
                                 hold,
                                 scene.reconstruction);
}

TEST(HeldBundleAdjustment, RigLensesKeepTheirIntrinsicsWhenHeld) {
  Scene scene = MakeScene(/*num_rigs=*/1, /*num_cameras=*/2);
  const auto before = Params(scene.reconstruction);
  DivergedCameraHold hold;
  ASSERT_TRUE(Adjust(scene, /*hold_rig_lenses=*/true, hold));
  EXPECT_EQ(Params(scene.reconstruction), before);
  EXPECT_TRUE(hold.Held().empty());

  // Released, the same adjustment moves them.
  ASSERT_TRUE(Adjust(scene, /*hold_rig_lenses=*/false, hold));
  const auto after = Params(scene.reconstruction);
  for (const auto& [camera_id, params] : before) {
    EXPECT_NE(after.at(camera_id)[0], params[0]) << camera_id;
  }
}

TEST(HeldBundleAdjustment, SingleCamerasAreRefinedAsUpstream) {
  Scene scene = MakeScene(/*num_rigs=*/2, /*num_cameras=*/1);
  const auto before = Params(scene.reconstruction);
  DivergedCameraHold hold;
  ASSERT_TRUE(Adjust(scene, /*hold_rig_lenses=*/true, hold));
  const auto after = Params(scene.reconstruction);
  for (const auto& [camera_id, params] : before) {
    EXPECT_NE(after.at(camera_id)[0], params[0]) << camera_id;
  }
}

}  // namespace
}  // namespace colmap
