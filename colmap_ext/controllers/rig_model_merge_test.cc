#include "colmap_ext/controllers/rig_model_merge.h"

#include "colmap/geometry/pose.h"
#include "colmap/scene/database_sqlite.h"
#include "colmap/scene/synthetic.h"
#include "colmap/util/file.h"

#include <gtest/gtest.h>

namespace colmap {
namespace {

// Frames of one rig of `num_cameras` cameras a few centimetres apart,
// every point seen by every image.
Reconstruction MakeRigScene(int num_cameras = 2) {
  SyntheticDatasetOptions options;
  options.num_rigs = 1;
  options.num_cameras_per_rig = num_cameras;
  options.num_frames_per_rig = 5;
  options.num_points3D = 150;
  options.sensor_from_rig_translation_stddev = 0.05;
  Reconstruction truth;
  std::shared_ptr<Database> database =
      Database::Open(kInMemorySqliteDatabasePath);
  SynthesizeDataset(options, &truth, database.get());
  return truth;
}

std::vector<frame_t> SortedFrameIds(const Reconstruction& reconstruction) {
  std::vector<frame_t> frame_ids = reconstruction.RegFrameIds();
  std::sort(frame_ids.begin(), frame_ids.end());
  return frame_ids;
}

// The model of the frames `keep` (indices into the sorted frame ids) as the
// mapper leaves it: the other frames deregistered and torn down.
Reconstruction SubModel(const Reconstruction& truth,
                        const std::vector<int>& keep) {
  Reconstruction model = truth;
  const std::vector<frame_t> frame_ids = SortedFrameIds(truth);
  for (int i = 0; i < static_cast<int>(frame_ids.size()); ++i) {
    if (std::find(keep.begin(), keep.end(), i) == keep.end()) {
      model.DeRegisterFrame(frame_ids[i]);
    }
  }
  model.TearDown();
  return model;
}

double MaxPoseError(const Reconstruction& model, const Reconstruction& truth) {
  double max_error = 0;
  for (const image_t image_id : truth.RegImageIds()) {
    if (!model.ExistsImage(image_id) ||
        !model.Image(image_id).HasPose()) {
      return std::numeric_limits<double>::infinity();
    }
    const Rigid3d& estimate = model.Image(image_id).CamFromWorld();
    const Rigid3d& expected = truth.Image(image_id).CamFromWorld();
    max_error = std::max(
        {max_error,
         estimate.rotation().angularDistance(expected.rotation()),
         (model.Image(image_id).ProjectionCenter() -
          truth.Image(image_id).ProjectionCenter())
             .norm()});
  }
  return max_error;
}

TEST(RigModelMerge, TwoModelsSharingOneRigFrameBecomeTheTruth) {
  const Reconstruction truth = MakeRigScene();
  // Frames 0-2 and 2-4: two cameras in common, too few for upstream's merge.
  Reconstruction tgt = SubModel(truth, {2, 3, 4});
  Reconstruction src = SubModel(truth, {0, 1, 2});
  ASSERT_EQ(src.NumRegFrames(), 3);
  ASSERT_EQ(tgt.NumRegFrames(), 3);
  EXPECT_EQ(SharedRigFrames(src, tgt),
            std::vector<frame_t>{SortedFrameIds(truth)[2]});
  // src in its own gauge: turned, moved and scaled.
  src.Transform(Sim3d(0.3,
                      Eigen::Quaterniond(Eigen::AngleAxisd(
                          1.2, Eigen::Vector3d(1, 2, 3).normalized())),
                      Eigen::Vector3d(5, -2, 7)));
  ASSERT_GT(MaxPoseError(src, SubModel(truth, {0, 1, 2})), 0.1);

  IncrementalPipelineOptions options;
  std::string why;
  ASSERT_TRUE(MergeRigModels(options, {}, 5, src, tgt, &why)) << why;
  EXPECT_EQ(tgt.NumRegFrames(), 5);
  EXPECT_EQ(tgt.NumRegImages(), truth.NumRegImages());
  EXPECT_LT(MaxPoseError(tgt, truth), 1e-6);
  // Every point of the truth is one point of the merged model.
  EXPECT_EQ(tgt.NumPoints3D(), truth.NumPoints3D());
  EXPECT_EQ(tgt.ComputeNumObservations(), truth.ComputeNumObservations());
}

TEST(RigModelMerge, RefusesModelsWithoutASharedRigFrame) {
  const Reconstruction truth = MakeRigScene();
  const Reconstruction src = SubModel(truth, {0, 1});
  Reconstruction tgt = SubModel(truth, {2, 3, 4});
  IncrementalPipelineOptions options;
  std::string why;
  EXPECT_TRUE(SharedRigFrames(src, tgt).empty());
  EXPECT_FALSE(MergeRigModels(options, {}, 5, src, tgt, &why));
  EXPECT_NE(why.find("share no frame"), std::string::npos) << why;
  EXPECT_EQ(tgt.NumRegFrames(), 3);
}

TEST(RigModelMerge, ModelsOfASingleCameraAreLeftAsUpstreamLeavesThem) {
  const Reconstruction truth = MakeRigScene(/*num_cameras=*/1);
  ReconstructionManager manager;
  *manager.Get(manager.Add()) = SubModel(truth, {0, 1, 2});
  *manager.Get(manager.Add()) = SubModel(truth, {2, 3, 4});
  EXPECT_TRUE(SharedRigFrames(*manager.Get(0), *manager.Get(1)).empty());
  const std::filesystem::path output =
      std::filesystem::path(testing::TempDir()) / "rig_model_merge_single";
  IncrementalPipelineOptions options;
  EXPECT_EQ(MergeModelsSharingRigFrames(options, {}, output, 2, manager), 0);
  EXPECT_EQ(manager.Size(), 2);
  EXPECT_EQ(manager.Get(0)->NumRegFrames(), 3);
  EXPECT_FALSE(std::filesystem::exists(output));
}

TEST(RigModelMerge, WithoutCommonPointsTheRigOffsetsGiveTheScale) {
  const Reconstruction truth = MakeRigScene();
  Reconstruction src = SubModel(truth, {0, 1, 2});
  src.Transform(Sim3d(2.5, Eigen::Quaterniond::Identity(),
                      Eigen::Vector3d(1, 0, 0)));
  IncrementalPipelineOptions options;
  std::string why;
  // More common points asked for than there are.
  Reconstruction tgt = SubModel(truth, {2, 3, 4});
  ASSERT_TRUE(MergeRigModels(options, {}, 100000, src, tgt, &why)) << why;
  EXPECT_EQ(tgt.NumRegFrames(), 5);
  EXPECT_LT(MaxPoseError(tgt, truth), 1e-6);

  // A rig without lens offsets gives no scale either.
  std::vector<rig_t> rig_ids;
  for (const auto& [rig_id, rig] : src.Rigs()) rig_ids.push_back(rig_id);
  for (const rig_t rig_id : rig_ids) {
    for (auto& [sensor_id, sensor_from_rig] : src.Rig(rig_id).NonRefSensors()) {
      sensor_from_rig->translation() = Eigen::Vector3d::Zero();
    }
  }
  tgt = SubModel(truth, {2, 3, 4});
  const size_t num_points = tgt.NumPoints3D();
  EXPECT_FALSE(MergeRigModels(options, {}, 100000, src, tgt, &why));
  EXPECT_NE(why.find("needed for the scale"), std::string::npos) << why;
  EXPECT_EQ(tgt.NumRegFrames(), 3);
  EXPECT_EQ(tgt.NumPoints3D(), num_points);
}

TEST(RigModelMerge, RefusesAMergeThatDoesNotHoldTogether) {
  Reconstruction truth = MakeRigScene();
  SyntheticNoiseOptions noise;
  noise.point2D_stddev = 0.5;
  SynthesizeNoise(noise, &truth);
  Reconstruction tgt = SubModel(truth, {2, 3, 4});
  const Reconstruction src = SubModel(truth, {0, 1, 2});
  const size_t num_points = tgt.NumPoints3D();
  // A point filter far below the keypoints' noise: the merged model keeps
  // almost none of the two models' observations.
  IncrementalPipelineOptions options;
  options.mapper.filter_max_reproj_error = 0.01;
  std::string why;
  EXPECT_FALSE(MergeRigModels(options, {}, 5, src, tgt, &why));
  EXPECT_NE(why.find("does not hold together"), std::string::npos) << why;
  EXPECT_EQ(tgt.NumRegFrames(), 3);
  EXPECT_EQ(tgt.NumPoints3D(), num_points);

  // The same models merge under the mapper's filter.
  options = IncrementalPipelineOptions();
  EXPECT_TRUE(MergeRigModels(options, {}, 5, src, tgt, &why)) << why;
  EXPECT_EQ(tgt.NumRegFrames(), 5);
}

TEST(RigModelMerge, RewritesTheOutputFoldersAfterAMerge) {
  const Reconstruction truth = MakeRigScene();
  ReconstructionManager manager;
  *manager.Get(manager.Add()) = SubModel(truth, {0, 1, 2});
  *manager.Get(manager.Add()) = SubModel(truth, {2, 3, 4});
  const std::filesystem::path output =
      std::filesystem::path(testing::TempDir()) / "rig_model_merge_test";
  std::filesystem::remove_all(output);
  std::filesystem::create_directories(output);
  for (size_t i = 0; i < manager.Size(); ++i) {
    CreateDirIfNotExists(output / std::to_string(i));
    manager.Get(i)->Write(output / std::to_string(i));
  }
  IncrementalPipelineOptions options;
  EXPECT_EQ(MergeModelsSharingRigFrames(options, {}, output, 2, manager), 1);
  ASSERT_EQ(manager.Size(), 1);
  EXPECT_FALSE(std::filesystem::exists(output / "1"));
  Reconstruction written;
  written.Read(output / "0");
  EXPECT_EQ(written.NumRegFrames(), 5);
  EXPECT_LT(MaxPoseError(written, truth), 1e-6);

  // One model left: nothing to merge.
  EXPECT_EQ(MergeModelsSharingRigFrames(options, {}, output, 1, manager), 0);
}

}  // namespace
}  // namespace colmap
