#include "colmap_ext/scene/rig_config.h"

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace colmap {
namespace {

std::filesystem::path WriteConfig(const std::string& name,
                                  const std::string& json) {
  const std::filesystem::path path =
      std::filesystem::path(testing::TempDir()) / name;
  std::ofstream(path) << json;
  return path;
}

std::string ReadError(const std::filesystem::path& path) {
  try {
    ReadCheckedRigConfig(path);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "";
}

TEST(RigConfig, ReadsPrefixSuffixPoseAndCamera) {
  const auto path = WriteConfig("good.json", R"([{"cameras": [
      {"image_prefix": "", "image_suffix": "_1.JPG", "ref_sensor": true},
      {"image_prefix": "", "image_suffix": "_2.JPG",
       "cam_from_rig_rotation": [0, 0, 2, 0],
       "cam_from_rig_translation": [0, 0, 0.1],
       "camera_model_name": "PINHOLE", "camera_params": [1, 1, 2, 2]}]}])");
  const std::vector<RigConfig> configs = ReadCheckedRigConfig(path);
  ASSERT_EQ(configs.size(), 1);
  ASSERT_EQ(configs[0].cameras.size(), 2);
  EXPECT_TRUE(configs[0].cameras[0].ref_sensor);
  EXPECT_EQ(configs[0].cameras[1].image_suffix, "_2.JPG");
  // The rotation is normalized.
  EXPECT_NEAR(configs[0].cameras[1].cam_from_rig->rotation().y(), 1.0, 1e-12);
  EXPECT_EQ(configs[0].cameras[1].camera->params.size(), 4);
}

TEST(RigConfig, ErrorsNameTheFileAndTheCamera) {
  const std::string ref = R"({"image_prefix": "a/", "ref_sensor": true})";
  const auto short_rotation = WriteConfig("rotation.json", "[{\"cameras\": [" +
      ref + R"(, {"image_prefix": "b/", "cam_from_rig_rotation": [1, 0, 0],
        "cam_from_rig_translation": [0, 0, 0]}]}])");
  const std::string error = ReadError(short_rotation);
  EXPECT_NE(error.find("rig config " + short_rotation.string()),
            std::string::npos);
  EXPECT_NE(error.find("camera with image_prefix \"b/\""), std::string::npos);
  EXPECT_NE(error.find("needs 4 numbers"), std::string::npos);

  EXPECT_NE(ReadError(WriteConfig("nan.json", "[{\"cameras\": [" + ref +
                R"(, {"image_prefix": "b/", "cam_from_rig_rotation": [1, 0, 0, 0],
                 "cam_from_rig_translation": [0, "x", 0]}]}])"))
                .find("finite numbers"),
            std::string::npos);
  EXPECT_NE(ReadError(WriteConfig("half.json", "[{\"cameras\": [" + ref +
                R"(, {"image_prefix": "b/",
                 "cam_from_rig_rotation": [1, 0, 0, 0]}]}])"))
                .find("or neither"),
            std::string::npos);
  EXPECT_NE(ReadError(WriteConfig("model.json", "[{\"cameras\": [" + ref +
                R"(, {"image_prefix": "b/", "camera_model_name": "NOPE",
                 "camera_params": [1]}]}])"))
                .find("unknown camera model NOPE"),
            std::string::npos);
  EXPECT_NE(ReadError(WriteConfig("params.json", "[{\"cameras\": [" + ref +
                R"(, {"image_prefix": "b/", "camera_model_name": "PINHOLE",
                 "camera_params": [1, 2]}]}])"))
                .find("number of camera_params of PINHOLE"),
            std::string::npos);
  EXPECT_NE(ReadError(WriteConfig("noref.json",
                                  R"([{"cameras": [{"image_prefix": "a/"}]}])"))
                .find("Rig must have one reference sensor"),
            std::string::npos);
}

TEST(RigConfig, FrameNameByPrefixAndSuffix) {
  RigConfig::RigCamera lens;
  lens.image_prefix = "cam1/";
  EXPECT_EQ(RigFrameName("cam1/0001.jpg", lens), "0001.jpg");
  EXPECT_EQ(RigFrameName("cam2/0001.jpg", lens), std::nullopt);
  EXPECT_EQ(RigFrameName("cam1/", lens), std::nullopt);
  lens.image_prefix = "";
  lens.image_suffix = "_2.JPG";
  EXPECT_EQ(RigFrameName("R0010_2.JPG", lens), "R0010");
  EXPECT_EQ(RigFrameName("R0010_1.JPG", lens), std::nullopt);
  lens.image_suffix = "";
  EXPECT_EQ(RigFrameName("R0010_2.JPG", lens), std::nullopt);
}

Image MakeImage(image_t image_id, const std::string& name) {
  Image image;
  image.SetImageId(image_id);
  image.SetName(name);
  image.SetCameraId(1);
  return image;
}

TEST(RigConfig, FrameLensesFindDuplicateAndMissingImages) {
  RigConfig config;
  config.cameras.resize(2);
  config.cameras[0].image_suffix = "_1.JPG";
  config.cameras[1].image_suffix = "_2.JPG";
  const Image a1 = MakeImage(1, "A_1.JPG");
  const Image a2 = MakeImage(2, "A_2.JPG");
  const Image b1 = MakeImage(3, "B_1.JPG");
  RigFrameLenses lenses(config);
  EXPECT_EQ(lenses.Add(0, a1), "A");
  EXPECT_EQ(lenses.Add(1, a1), std::nullopt);
  EXPECT_EQ(lenses.Add(1, a2), "A");
  EXPECT_EQ(lenses.Add(0, b1), "B");
  EXPECT_THROW(lenses.Add(1, a2), std::invalid_argument);
  try {
    lenses.CheckComplete();
    ADD_FAILURE() << "frame B lacks its second image";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("(expected B_2.JPG)"),
              std::string::npos);
  }
  EXPECT_EQ(lenses.DataId(a2).sensor_id.id, 1);
}

}  // namespace
}  // namespace colmap
