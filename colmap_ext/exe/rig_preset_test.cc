// Every camera preset's rig_config.json, read by COLMAP's own rig config
// reader (colmap/scene/rig.cc as patched): the same lenses, reference
// sensor, poses and cameras that the preset says.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

#include "calibration/camera_presets.h"
#include "colmap/scene/rig.h"
#include "colmap/sensor/models.h"

namespace colmap {
namespace {

TEST(RigPreset, RigConfigReaderAcceptsEveryPreset) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("rig_preset_test_" + std::to_string(::getpid()) + ".json");
  for (const sphera::CameraPreset& preset : sphera::CameraPresets()) {
    const sphera::PresetResolution resolution =
        preset.any_two_to_one_size
            ? sphera::FindPresetResolution(preset, 3840, 1920)
            : preset.resolutions.front();
    {
      std::ofstream file(path);
      file << sphera::PresetRigConfigJson(preset, resolution);
    }
    std::vector<RigConfig> configs;
    ASSERT_NO_THROW(configs = ReadRigConfig(path)) << preset.name;
    ASSERT_EQ(configs.size(), 1u) << preset.name;
    const std::vector<RigConfig::RigCamera>& cameras = configs[0].cameras;
    ASSERT_EQ(cameras.size(), preset.lenses.size()) << preset.name;
    for (size_t lens = 0; lens < cameras.size(); ++lens) {
      const std::string where = preset.name + " lens " + std::to_string(lens);
      EXPECT_EQ(cameras[lens].ref_sensor, lens == 0) << where;
      ASSERT_TRUE(cameras[lens].camera.has_value()) << where;
      const sphera::PresetCamera expected =
          sphera::PresetLensCamera(preset, resolution, static_cast<int>(lens));
      EXPECT_EQ(cameras[lens].camera->ModelName(), expected.model_name)
          << where;
      EXPECT_EQ(cameras[lens].camera->params, expected.params) << where;
      EXPECT_TRUE(CameraModelVerifyParams(cameras[lens].camera->model_id,
                                          cameras[lens].camera->params))
          << where;
      if (lens == 0) continue;
      ASSERT_TRUE(cameras[lens].cam_from_rig.has_value()) << where;
      const Rigid3d& cam_from_rig = *cameras[lens].cam_from_rig;
      EXPECT_NEAR(std::abs(cam_from_rig.rotation().dot(
                      sphera::PresetCamFromRigRotation(
                          preset, static_cast<int>(lens)))),
                  1,
                  1e-12)
          << where;
      EXPECT_LT((cam_from_rig.translation() -
                 sphera::PresetCamFromRigTranslation(preset,
                                                     static_cast<int>(lens)))
                    .norm(),
                1e-12)
          << where;
    }
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace colmap
