#include "colmap_ext/sfm/rig_initial_pair.h"

#include "colmap/geometry/pose.h"
#include "colmap/scene/database_sqlite.h"
#include "colmap/scene/synthetic.h"

#include <gtest/gtest.h>

namespace colmap {
namespace {

struct SyntheticScene {
  Reconstruction truth;
  std::shared_ptr<DatabaseCache> cache;
};

// Frames of rigs of `num_cameras` perspective cameras, each lens a few
// centimetres from the rig's origin, all points seen by every image.
SyntheticScene MakeScene(int num_cameras, double offset_stddev = 0.05) {
  SyntheticDatasetOptions options;
  options.num_rigs = 1;
  options.num_cameras_per_rig = num_cameras;
  options.num_frames_per_rig = 4;
  options.num_points3D = 200;
  options.sensor_from_rig_translation_stddev = offset_stddev;
  SyntheticScene scene;
  std::shared_ptr<Database> database =
      Database::Open(kInMemorySqliteDatabasePath);
  SynthesizeDataset(options, &scene.truth, database.get());
  scene.cache = DatabaseCache::Create(*database, DatabaseCache::Options());
  return scene;
}

// Two images of different frames, of different lenses when there are two.
std::pair<image_t, image_t> ImagesOfTwoFrames(const Reconstruction& truth) {
  std::vector<frame_t> frame_ids;
  for (const auto& [frame_id, frame] : truth.Frames()) {
    frame_ids.push_back(frame_id);
  }
  std::sort(frame_ids.begin(), frame_ids.end());
  const auto ids1 = truth.Frame(frame_ids[0]).ImageIds();
  const auto ids2 = truth.Frame(frame_ids[1]).ImageIds();
  std::vector<image_t> images1;
  std::vector<image_t> images2;
  for (const data_t& data_id : ids1) images1.push_back(data_id.id);
  for (const data_t& data_id : ids2) images2.push_back(data_id.id);
  return {images1.front(), images2.back()};
}

IncrementalMapper::Options MapperOptions() {
  IncrementalMapper::Options options;
  options.init_min_num_inliers = 50;
  options.init_min_tri_angle = 1;
  options.random_seed = 1;
  return options;
}

TEST(RigInitialPair, RecoversTheRelativePoseOfTwoImagesFromAllLenses) {
  const SyntheticScene scene = MakeScene(/*num_cameras=*/3);
  const auto [image_id1, image_id2] = ImagesOfTwoFrames(scene.truth);
  ASSERT_TRUE(IsRigFramePair(*scene.cache, image_id1, image_id2));
  const std::optional<IncrementalMapperImpl::InitInfo> info =
      EstimateInitialRigFramePair(
          MapperOptions(), *scene.cache, image_id1, image_id2);
  ASSERT_TRUE(info.has_value());
  EXPECT_EQ(info->image_id1, image_id1);
  EXPECT_EQ(info->image_id2, image_id2);
  // Metric: the lens offsets in the rig fix the scale.
  const Rigid3d truth = scene.truth.Image(image_id2).CamFromWorld() *
                        Inverse(scene.truth.Image(image_id1).CamFromWorld());
  EXPECT_LT(truth.rotation().angularDistance(info->cam2_from_cam1.rotation()),
            1e-6);
  EXPECT_LT((truth.translation() - info->cam2_from_cam1.translation()).norm(),
            1e-6 * truth.translation().norm());

  // The angle and inlier thresholds bite; images of one frame never pair.
  IncrementalMapper::Options strict = MapperOptions();
  strict.init_min_tri_angle = 179;
  EXPECT_FALSE(EstimateInitialRigFramePair(
                   strict, *scene.cache, image_id1, image_id2)
                   .has_value());
  strict = MapperOptions();
  strict.init_min_num_inliers = 100000;
  EXPECT_FALSE(EstimateInitialRigFramePair(
                   strict, *scene.cache, image_id1, image_id2)
                   .has_value());
  const frame_t frame_id1 = scene.cache->Image(image_id1).FrameId();
  for (const data_t& data_id : scene.cache->Frame(frame_id1).ImageIds()) {
    if (data_id.id != image_id1) {
      EXPECT_FALSE(EstimateInitialRigFramePair(
                       MapperOptions(), *scene.cache, image_id1, data_id.id)
                       .has_value());
    }
  }
}

TEST(RigInitialPair, LensesSharingOneCentreInitializeUpToScale) {
  // A rig config without offsets: the frames are panoramas.
  const SyntheticScene scene = MakeScene(/*num_cameras=*/2, 0.0);
  const auto [image_id1, image_id2] = ImagesOfTwoFrames(scene.truth);
  const std::optional<IncrementalMapperImpl::InitInfo> info =
      EstimateInitialRigFramePair(
          MapperOptions(), *scene.cache, image_id1, image_id2);
  ASSERT_TRUE(info.has_value());
  const Rigid3d truth = scene.truth.Image(image_id2).CamFromWorld() *
                        Inverse(scene.truth.Image(image_id1).CamFromWorld());
  EXPECT_LT(truth.rotation().angularDistance(info->cam2_from_cam1.rotation()),
            1e-6);
  EXPECT_GT(truth.translation().normalized().dot(
                info->cam2_from_cam1.translation().normalized()),
            1 - 1e-9);
}

TEST(RigInitialPair, AFramePairIsTriedOnceForAllItsLenses) {
  const SyntheticScene scene = MakeScene(/*num_cameras=*/3);
  const auto [image_id1, image_id2] = ImagesOfTwoFrames(scene.truth);
  FlatHashSet<image_pair_t> tried;
  MarkFramePairTried(*scene.cache, image_id1, image_id2, &tried);
  EXPECT_EQ(tried.size(), 9);
  const frame_t frame_id2 = scene.cache->Image(image_id2).FrameId();
  for (const data_t& data_id : scene.cache->Frame(frame_id2).ImageIds()) {
    EXPECT_EQ(tried.count(ImagePairToPairId(image_id1, data_id.id)), 1);
  }
}

TEST(RigInitialPair, SingleCamerasKeepUpstreamsSearch) {
  const SyntheticScene scene = MakeScene(/*num_cameras=*/1);
  const auto [image_id1, image_id2] = ImagesOfTwoFrames(scene.truth);
  EXPECT_FALSE(IsRigFramePair(*scene.cache, image_id1, image_id2));
  FlatHashSet<image_pair_t> tried;
  MarkFramePairTried(*scene.cache, image_id1, image_id2, &tried);
  EXPECT_TRUE(tried.empty());
  const IncrementalMapper::Options options = MapperOptions();
  EXPECT_EQ(InitialTriangulationMinAngle(options, 1.5, scene.truth, image_id1),
            options.init_min_tri_angle);
  const SyntheticScene rig = MakeScene(/*num_cameras=*/2);
  EXPECT_EQ(InitialTriangulationMinAngle(
                options, 1.5, rig.truth, ImagesOfTwoFrames(rig.truth).first),
            1.5);
}

}  // namespace
}  // namespace colmap
