#include "synthetic/rig.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "camera_models/registry.h"

namespace sphera {
namespace synthetic {
namespace {

namespace fs = std::filesystem;

fs::path FreshPath(const std::string& name) {
  const fs::path path =
      fs::path(::testing::TempDir()) / ("sphera_rig_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(path);
  fs::remove_all(path.string() + ".tmp");
  return path;
}

std::vector<std::vector<std::string>> DataRows(const fs::path& path) {
  std::ifstream file(path);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(file, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    std::vector<std::string> row;
    std::string token;
    while (in >> token) row.push_back(token);
    rows.push_back(row);
  }
  return rows;
}

Eigen::Vector3d CentreInRig(const RigSensor& sensor) {
  return -(sensor.sensor_from_rig_rotation.conjugate() * sensor.sensor_from_rig_translation);
}

Eigen::Vector3d AxisInRig(const RigSensor& sensor) {
  return sensor.sensor_from_rig_rotation.conjugate() * Eigen::Vector3d::UnitZ();
}

TEST(RigPreset, DualFisheyeIsTwoBackToBack200DegreeLenses3cmApart) {
  std::vector<RigSensor> sensors;
  ASSERT_EQ(MakeRigPreset("dual_fisheye", 512, &sensors), "");
  ASSERT_EQ(sensors.size(), 2u);
  EXPECT_EQ(sensors[0].name, "lens0");
  EXPECT_EQ(sensors[1].name, "lens1");
  EXPECT_NEAR((CentreInRig(sensors[1]) - CentreInRig(sensors[0])).norm(), 0.03, 1e-12);
  EXPECT_NEAR(AxisInRig(sensors[0]).dot(AxisInRig(sensors[1])), -1, 1e-12);
  // The baseline runs along the axes (lenses back to back).
  EXPECT_NEAR(std::abs(CentreInRig(sensors[1]).normalized().dot(AxisInRig(sensors[0]))), 1,
              1e-12);
  for (const RigSensor& sensor : sensors) {
    EXPECT_EQ(sensor.width, 512);
    EXPECT_DOUBLE_EQ(sensor.max_angle_deg, 100);
    Eigen::Vector3d circle;
    ASSERT_EQ(ImageCircle(sensor, &circle), "");
    EXPECT_NEAR(circle.z(), 0.47 * 512, 0.01 * 0.47 * 512) << sensor.name;
    // A ray 100 degrees off the axis, 10 degrees beyond the hemisphere,
    // projects into the image.
    Eigen::Vector2d pixel;
    const double a = 99.5 * M_PI / 180;
    ASSERT_TRUE(ImageFromRay(ModelIdFromName(sensor.model_name), sensor.params,
                             Eigen::Vector3d(0, std::sin(a), std::cos(a)), &pixel));
    EXPECT_LT((pixel - circle.head<2>()).norm(), circle.z());
  }
  // Real lenses differ: not the same intrinsics.
  EXPECT_NE(sensors[0].model_name, sensors[1].model_name);
}

TEST(RigPreset, Ring8IsEightOutwardLensesOn6cmRing) {
  std::vector<RigSensor> sensors;
  ASSERT_EQ(MakeRigPreset("ring8", 0, &sensors), "");
  ASSERT_EQ(sensors.size(), 8u);
  // Ring centre: the mean of the lens centres.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const RigSensor& sensor : sensors) mean += CentreInRig(sensor) / 8;
  for (size_t k = 0; k < 8; ++k) {
    const Eigen::Vector3d offset = CentreInRig(sensors[k]) - mean;
    EXPECT_NEAR(Eigen::Vector2d(offset.x(), offset.z()).norm(), 0.06, 1e-9) << k;
    // Outward looking, horizontal.
    EXPECT_NEAR(AxisInRig(sensors[k]).dot(Eigen::Vector3d(offset.x(), 0, offset.z()).normalized()),
                1, 1e-9);
    EXPECT_EQ(sensors[k].width, 640);
    Eigen::Vector3d circle;
    EXPECT_EQ(ImageCircle(sensors[k], &circle), "");
  }
  EXPECT_NE(MakeRigPreset("triple", 0, &sensors).find("unknown rig preset 'triple'"),
            std::string::npos);
}

TEST(RigSensors, ReadsFileAndRefusesNonIdentityReference) {
  const fs::path dir = FreshPath("sensors");
  fs::create_directories(dir);
  {
    std::ofstream file(dir / "ok.txt");
    file << "# two lenses\n"
         << "front EUCM 64 64 20 20 32 32 0.6 1 | 1 0 0 0 0 0 0 95\n"
         << "back EUCM 64 64 20 20 32 32 0.6 1 | 0 0 1 0 0 0 -0.02 95\n";
  }
  std::vector<RigSensor> sensors;
  ASSERT_EQ(ReadRigSensors((dir / "ok.txt").string(), &sensors), "");
  ASSERT_EQ(sensors.size(), 2u);
  EXPECT_EQ(sensors[1].name, "back");
  EXPECT_DOUBLE_EQ(sensors[1].max_angle_deg, 95);
  EXPECT_NEAR(CentreInRig(sensors[1]).z(), -0.02, 1e-12);
  {
    std::ofstream file(dir / "bad.txt");
    file << "front EUCM 64 64 20 20 32 32 0.6 1 | 0 0 1 0 0 0 0\n";
  }
  const std::string error = ReadRigSensors((dir / "bad.txt").string(), &sensors);
  EXPECT_NE(error.find("bad.txt:1"), std::string::npos) << error;
  EXPECT_NE(error.find("reference"), std::string::npos) << error;
  fs::remove_all(dir);
}

TEST(RigPreset, ImageCircleOutsideTheImageIsRefused) {
  RigSensor sensor;
  sensor.name = "wide";
  sensor.model_name = "EUCM";
  sensor.width = sensor.height = 100;
  sensor.params = {40, 40, 50, 50, 0.6, 1.0};
  sensor.max_angle_deg = 100;
  Eigen::Vector3d circle;
  const std::string error = ImageCircle(sensor, &circle);
  EXPECT_NE(error.find("lens 'wide'"), std::string::npos) << error;
  EXPECT_NE(error.find("not inside"), std::string::npos) << error;
}

TEST(FramePath, FramesAreDistinctAndEveryLensIsInFreeSpace) {
  const Scene scene(SceneOptions{});
  std::vector<RigSensor> sensors;
  ASSERT_EQ(MakeRigPreset("ring8", 64, &sensors), "");
  const std::vector<RigFrame> frames = MakeFramePath(12, 3);
  ASSERT_EQ(frames.size(), 12u);
  for (size_t f = 0; f < frames.size(); ++f) {
    const Eigen::Vector3d centre =
        -(frames[f].rig_from_world_rotation.conjugate() * frames[f].rig_from_world_translation);
    if (f > 0) {
      const Eigen::Vector3d previous = -(frames[f - 1].rig_from_world_rotation.conjugate() *
                                         frames[f - 1].rig_from_world_translation);
      EXPECT_GT((centre - previous).norm(), 0.2);
    }
    for (const RigSensor& sensor : sensors) {
      const Eigen::Vector3d lens = centre + frames[f].rig_from_world_rotation.conjugate() *
                                                CentreInRig(sensor);
      EXPECT_TRUE(scene.IsFreeSpace(lens)) << f;
    }
  }
}

TEST(RigDataset, WritesLensesMasksRigsFramesRawAndStitched) {
  const fs::path dir = FreshPath("dual");
  const Scene scene(SceneOptions{});
  std::vector<RigSensor> sensors;
  ASSERT_EQ(MakeRigPreset("dual_fisheye", 48, &sensors), "");
  const std::vector<RigFrame> frames = MakeFramePath(3, 0);
  RigDatasetOptions options;
  options.dataset.render.supersample = 1;
  options.dataset.num_points = 40;
  options.image_extension = ".png";
  options.raw = true;
  options.stitched = true;
  options.stitched_width = 64;
  ASSERT_EQ(WriteRigDataset(dir.string(), scene, sensors, frames, options, nullptr), "");

  // One camera per lens, a rig of two sensors, three frames of two images.
  EXPECT_EQ(DataRows(dir / "sparse_gt" / "cameras.txt").size(), 2u);
  const auto rigs = DataRows(dir / "sparse_gt" / "rigs.txt");
  ASSERT_EQ(rigs.size(), 1u);
  ASSERT_EQ(rigs[0].size(), 4u + 3 + 7);
  EXPECT_EQ(rigs[0][1], "2");
  const Eigen::Quaterniond q(std::stod(rigs[0][7]), std::stod(rigs[0][8]), std::stod(rigs[0][9]),
                             std::stod(rigs[0][10]));
  EXPECT_LT(q.angularDistance(sensors[1].sensor_from_rig_rotation), 1e-12);
  const auto frame_rows = DataRows(dir / "sparse_gt" / "frames.txt");
  ASSERT_EQ(frame_rows.size(), 3u);
  for (const auto& row : frame_rows) {
    ASSERT_EQ(row.size(), 2u + 7 + 1 + 6);
    EXPECT_EQ(row[9], "2");
  }
  // Every image's pose is its lens's sensor_from_rig after its frame's rig_from_world.
  const auto images = DataRows(dir / "sparse_gt" / "images.txt");
  int checked = 0;
  for (const auto& row : images) {
    if (row.size() != 10) continue;  // a POINTS2D line
    const std::string name = row[9];
    const int sensor = name.rfind("lens1/", 0) == 0 ? 1 : 0;
    const int frame = std::stoi(name.substr(name.find("frame") + 5, 3));
    const Eigen::Quaterniond rotation(std::stod(row[1]), std::stod(row[2]), std::stod(row[3]),
                                      std::stod(row[4]));
    const Eigen::Vector3d translation(std::stod(row[5]), std::stod(row[6]), std::stod(row[7]));
    const Eigen::Quaterniond expected_rotation =
        sensors[sensor].sensor_from_rig_rotation * frames[frame].rig_from_world_rotation;
    const Eigen::Vector3d expected_translation =
        sensors[sensor].sensor_from_rig_rotation * frames[frame].rig_from_world_translation +
        sensors[sensor].sensor_from_rig_translation;
    EXPECT_LT(rotation.angularDistance(expected_rotation), 1e-12) << name;
    EXPECT_LT((translation - expected_translation).norm(), 1e-12) << name;
    EXPECT_EQ(row[8], std::to_string(sensor + 1)) << name;
    ++checked;
  }
  EXPECT_EQ(checked, 6);

  // Masks are the image circle; the image is black outside it; the raw
  // frame is both lenses side by side, pixel for pixel.
  const auto circles = DataRows(dir / "circles.txt");
  ASSERT_EQ(circles.size(), 2u);
  for (int f = 0; f < 3; ++f) {
    const std::string frame = "frame00" + std::to_string(f) + ".png";
    std::vector<cv::Mat> lenses;
    for (int k = 0; k < 2; ++k) {
      const std::string name = "lens" + std::to_string(k) + "/" + frame;
      const cv::Mat image = cv::imread((dir / "images" / name).string(), cv::IMREAD_COLOR);
      const cv::Mat mask =
          cv::imread((dir / "masks" / (name + ".png")).string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(image.empty()) << name;
      ASSERT_EQ(mask.type(), CV_8U) << name;
      const double cx = std::stod(circles[k][1]), cy = std::stod(circles[k][2]),
                   r = std::stod(circles[k][3]);
      int inside = 0, lit_outside = 0;
      for (int row = 0; row < mask.rows; ++row) {
        for (int col = 0; col < mask.cols; ++col) {
          const bool in = std::hypot(col + 0.5 - cx, row + 0.5 - cy) <= r;
          ASSERT_EQ(mask.at<uint8_t>(row, col), in ? 255 : 0) << name << " " << col << "," << row;
          inside += in;
          if (!in && image.at<cv::Vec3b>(row, col) != cv::Vec3b(0, 0, 0)) ++lit_outside;
        }
      }
      EXPECT_GT(inside, 0.6 * mask.total());
      EXPECT_LT(inside, mask.total());
      EXPECT_EQ(lit_outside, 0) << name;
      lenses.push_back(image);
    }
    const cv::Mat raw = cv::imread((dir / "raw" / frame).string(), cv::IMREAD_COLOR);
    ASSERT_EQ(raw.cols, 96);
    ASSERT_EQ(raw.rows, 48);
    EXPECT_EQ(cv::norm(raw(cv::Rect(0, 0, 48, 48)), lenses[0], cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(raw(cv::Rect(48, 0, 48, 48)), lenses[1], cv::NORM_INF), 0);
    const cv::Mat panorama =
        cv::imread((dir / "stitched" / "images" / frame).string(), cv::IMREAD_COLOR);
    EXPECT_EQ(panorama.cols, 64);
    EXPECT_EQ(panorama.rows, 32);
  }
  EXPECT_EQ(DataRows(dir / "stitched" / "sparse_gt" / "images.txt").size(), 3u);
  // rig_config.json names both prefixes and the reference.
  std::ifstream json_file(dir / "rig_config.json");
  const std::string json((std::istreambuf_iterator<char>(json_file)),
                         std::istreambuf_iterator<char>());
  EXPECT_NE(json.find("\"image_prefix\": \"lens1/\""), std::string::npos);
  EXPECT_NE(json.find("\"ref_sensor\": true"), std::string::npos);
  EXPECT_NE(json.find("\"camera_model_name\": \"DOUBLE_SPHERE\""), std::string::npos);
  fs::remove_all(dir);
}

// Stitching lenses that really share a centre gives the panorama rendered
// directly from that centre; with the 3 cm baseline the seam shows parallax.
TEST(Stitch, LensesWithOneCentreGiveTheDirectPanorama) {
  const Scene scene(SceneOptions{});
  std::vector<RigSensor> sensors;
  ASSERT_EQ(MakeRigPreset("dual_fisheye", 256, &sensors), "");
  const Eigen::Matrix3d world_from_rig =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d centre(0.2, 0.1, -0.3);
  auto panorama_of = [&](double baseline_scale) {
    auto spec = std::make_shared<StitchSpec>();
    for (const RigSensor& sensor : sensors) {
      const Eigen::Matrix3d world_from_lens =
          world_from_rig * sensor.sensor_from_rig_rotation.conjugate().toRotationMatrix();
      // Lens centres about `centre`, scaled baseline.
      const Eigen::Vector3d lens_centre =
          centre + world_from_rig * (baseline_scale * (CentreInRig(sensor) -
                                                       0.5 * (CentreInRig(sensors[0]) +
                                                              CentreInRig(sensors[1]))));
      VirtualCamera lens = MakeCamera("l.png", sensor.model_name, sensor.width, sensor.height,
                                      sensor.params, world_from_lens, lens_centre);
      EXPECT_EQ(ImageCircle(sensor, &lens.image_circle), "");
      spec->lenses.push_back(lens);
    }
    VirtualCamera panorama =
        MakeCamera("p.png", "EQUIRECTANGULAR", 128, 64, {128, 64}, world_from_rig, centre);
    panorama.stitch = spec;
    EXPECT_EQ(panorama.Check(), "");
    RenderOptions options;
    options.supersample = 1;
    return Render(scene, panorama, options).image;
  };
  const VirtualCamera direct =
      MakeCamera("d.png", "EQUIRECTANGULAR", 128, 64, {128, 64}, world_from_rig, centre);
  RenderOptions options;
  options.supersample = 1;
  const cv::Mat reference = Render(scene, direct, options).image;
  EXPECT_LE(cv::norm(panorama_of(0.0), reference, cv::NORM_INF), 1);
  const cv::Mat parallax = panorama_of(1.0);
  EXPECT_GT(cv::norm(parallax, reference, cv::NORM_L1), 0);
  // A stitched panorama's lens must be a plain lens.
  VirtualCamera nested = direct;
  auto spec = std::make_shared<StitchSpec>();
  VirtualCamera inner = direct;
  inner.stitch = std::make_shared<StitchSpec>();
  spec->lenses.push_back(inner);
  nested.stitch = spec;
  EXPECT_NE(nested.Check().find("cannot itself be stitched"), std::string::npos);
}

TEST(VirtualCamera, NamesMayHaveOneFolder) {
  VirtualCamera camera =
      MakeCamera("lens0/frame000.jpg", "PINHOLE", 40, 30, {20, 20, 20, 15},
                 Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  EXPECT_EQ(camera.Check(), "");
  for (const char* bad : {"a/b/c.jpg", "/a.jpg", "a/", "../a.jpg", "./a.jpg", "a b.jpg"}) {
    camera.name = bad;
    EXPECT_NE(camera.Check(), "") << bad;
  }
}

}  // namespace
}  // namespace synthetic
}  // namespace sphera
