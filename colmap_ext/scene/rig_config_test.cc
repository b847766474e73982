#include "colmap_ext/scene/rig_config.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "colmap/math/math.h"

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

TEST(RigConfig, LensFromItsFieldOfViewAndImageCircle) {
  // A 195° lens whose circle of radius 560 px the frame crops (its centre
  // 300 px below the top edge): UNIFIED_OMNI started from the equidistant
  // lens of that circle, which puts the axis on the circle's centre and the
  // ray at 97.5° on the circle.
  const auto path = WriteConfig("spec.json", R"([{"cameras": [
      {"image_prefix": "a/", "ref_sensor": true,
       "camera_model_name": "UNIFIED_OMNI", "field_of_view_deg": 195,
       "image_circle": [800.5, 300, 560]}]}])");
  const std::vector<RigConfig> configs = ReadCheckedRigConfig(path);
  ASSERT_TRUE(configs[0].cameras[0].camera.has_value());
  Camera camera = *configs[0].cameras[0].camera;
  EXPECT_EQ(camera.ModelName(), "UNIFIED_OMNI");
  ASSERT_EQ(camera.params.size(), CameraModelNumParams(camera.model_id));
  camera.width = 1600;
  camera.height = 1088;
  const Eigen::Vector2d centre(800.5, 300);
  const auto pixel_at = [&](double theta_deg) {
    const double theta = DegToRad(theta_deg);
    const std::optional<Eigen::Vector2d> pixel = camera.ImgFromCam(
        Eigen::Vector3d(std::sin(theta), 0, std::cos(theta)));
    return pixel ? (*pixel - centre).norm() : -1.0;
  };
  EXPECT_NEAR(pixel_at(0), 0, 1.0);
  EXPECT_NEAR(pixel_at(45), 560 * 45 / 97.5, 2.8);
  EXPECT_NEAR(pixel_at(97.5), 560, 2.8);

  // Each half of the pair, both ways of giving the intrinsics, no model,
  // and values that start no lens are errors naming the camera.
  const std::string ref = R"({"image_prefix": "a/", "ref_sensor": true})";
  const auto error_of = [&](const std::string& name, const std::string& lens) {
    return ReadError(WriteConfig(name, "[{\"cameras\": [" + ref +
                                           R"(, {"image_prefix": "b/", )" +
                                           lens + "}]}]"));
  };
  for (const auto& [lens, expected] :
       std::vector<std::pair<std::string, std::string>>{
           {R"("camera_model_name": "EUCM", "field_of_view_deg": 190)",
            "give field_of_view_deg and image_circle, or neither"},
           {R"("camera_model_name": "EUCM", "image_circle": [1, 2, 3])",
            "give field_of_view_deg and image_circle, or neither"},
           {R"("camera_model_name": "EUCM", "camera_params": [1, 1, 1, 1, 0.5,
              1], "field_of_view_deg": 190, "image_circle": [1, 2, 3])",
            "not both"},
           {R"("field_of_view_deg": 190, "image_circle": [1, 2, 3])",
            "give camera_model_name"},
           {R"("camera_model_name": "EUCM", "field_of_view_deg": 190,
              "image_circle": [1, 2])",
            "image_circle needs 3 numbers"},
           {R"("camera_model_name": "EUCM", "field_of_view_deg": "wide",
              "image_circle": [1, 2, 3])",
            "field_of_view_deg must be a number"},
           {R"("camera_model_name": "EUCM", "field_of_view_deg": 400,
              "image_circle": [1, 2, 3])",
            "field of view"},
           {R"("camera_model_name": "EUCM", "field_of_view_deg": 190,
              "image_circle": [1, 2, 0])",
            "image circle"},
           {R"("camera_model_name": "PINHOLE", "field_of_view_deg": 90,
              "image_circle": [1, 2, 3])",
            "PINHOLE: not a model for"}}) {
    const std::string error = error_of("lens.json", lens);
    EXPECT_NE(error.find("camera with image_prefix \"b/\""), std::string::npos)
        << lens << ": " << error;
    EXPECT_NE(error.find(expected), std::string::npos) << lens << ": " << error;
  }
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
