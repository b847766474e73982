#include "synthetic/model_io.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "camera_models/registry.h"
#include "synthetic/file_formats.h"

namespace sphera {
namespace synthetic {
namespace {

namespace fs = std::filesystem;

fs::path FreshPath(const std::string& name) {
  const fs::path path =
      fs::path(::testing::TempDir()) / ("sphera_syn_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(path);
  fs::remove_all(path.string() + ".tmp");
  return path;
}

std::vector<std::string> DataLines(const fs::path& path) {
  std::ifstream file(path);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(file, line)) {
    if (!line.empty() && line[0] == '#') continue;
    lines.push_back(line);
  }
  return lines;
}

std::vector<VirtualCamera> SmallCameras() {
  return {MakeCamera("a.jpg", "EQUIRECTANGULAR", 64, 32, {64, 32}, Eigen::Matrix3d::Identity(),
                     Eigen::Vector3d(-0.5, 0, 0)),
          MakeCamera("b.png", "EQUIRECTANGULAR", 64, 32, {64, 32}, Eigen::Matrix3d::Identity(),
                     Eigen::Vector3d(0.5, 0.1, 0.2)),
          MakeCamera("c.jpg", "PINHOLE", 40, 30, {20, 20, 20, 15},
                     Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                     Eigen::Vector3d(0, -0.2, -0.5))};
}

DatasetOptions SmallOptions() {
  DatasetOptions options;
  options.render.supersample = 1;
  options.num_points = 60;
  return options;
}

TEST(Dataset, WritesColmapTextGroundTruthAtomically) {
  const fs::path dir = FreshPath("ok");
  const Scene scene(SceneOptions{});
  const std::vector<VirtualCamera> cameras = SmallCameras();
  ASSERT_EQ(WriteDataset(dir.string(), scene, cameras, SmallOptions(), nullptr), "");
  EXPECT_FALSE(fs::exists(dir.string() + ".tmp"));
  for (const char* file : {"images/a.jpg", "images/b.png", "images/c.jpg",
                           "depth/a.jpg.depth.bin", "depth/c.jpg.depth.bin",
                           "sparse_gt/cameras.txt", "sparse_gt/images.txt",
                           "sparse_gt/points3D.txt", "rig.txt"}) {
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  }
  EXPECT_EQ(cv::imread((dir / "images/b.png").string()).cols, 64);
  RangeMap depth;
  ASSERT_EQ(ReadRangeMap((dir / "depth/c.jpg.depth.bin").string(), &depth), "");
  EXPECT_EQ(depth.width, 40);
  EXPECT_EQ(depth.height, 30);

  // Identical intrinsics share a camera.
  const std::vector<std::string> camera_lines = DataLines(dir / "sparse_gt/cameras.txt");
  ASSERT_EQ(camera_lines.size(), 2u);
  EXPECT_EQ(camera_lines[0], "1 EQUIRECTANGULAR 64 32 64 32");
  EXPECT_EQ(camera_lines[1], "2 PINHOLE 40 30 20 20 20 15");

  // images.txt: pose line and POINTS2D line per image; check the poses and
  // that every track entry points at an observation of its point.
  const std::vector<std::string> image_lines = DataLines(dir / "sparse_gt/images.txt");
  ASSERT_EQ(image_lines.size(), 6u);
  std::vector<std::vector<std::pair<Eigen::Vector2d, int>>> points2d(3);
  for (int i = 0; i < 3; ++i) {
    std::istringstream pose_line(image_lines[2 * i]);
    int image_id, camera_id;
    double qw, qx, qy, qz, tx, ty, tz;
    std::string name;
    ASSERT_TRUE(pose_line >> image_id >> qw >> qx >> qy >> qz >> tx >> ty >> tz >> camera_id >> name);
    EXPECT_EQ(image_id, i + 1);
    EXPECT_EQ(name, cameras[i].name);
    EXPECT_EQ(camera_id, i < 2 ? 1 : 2);
    const Eigen::Quaterniond q(qw, qx, qy, qz);
    EXPECT_LT((q.toRotationMatrix() - cameras[i].cam_from_world_rotation.toRotationMatrix()).norm(), 1e-12);
    EXPECT_LT((Eigen::Vector3d(tx, ty, tz) - cameras[i].cam_from_world_translation).norm(), 1e-12);
    std::istringstream point_line(image_lines[2 * i + 1]);
    double x, y;
    int point_id;
    while (point_line >> x >> y >> point_id) points2d[i].push_back({Eigen::Vector2d(x, y), point_id});
  }
  const std::vector<std::string> point_lines = DataLines(dir / "sparse_gt/points3D.txt");
  EXPECT_GT(point_lines.size(), 20u);
  for (const std::string& line : point_lines) {
    std::istringstream in(line);
    int point_id, r, g, b;
    double x, y, z, error;
    ASSERT_TRUE(in >> point_id >> x >> y >> z >> r >> g >> b >> error);
    int image_id, point2d_idx, track_length = 0;
    while (in >> image_id >> point2d_idx) {
      ++track_length;
      ASSERT_GE(image_id, 1);
      ASSERT_LE(image_id, 3);
      ASSERT_LT(point2d_idx, static_cast<int>(points2d[image_id - 1].size()));
      const auto& [pixel, observed_id] = points2d[image_id - 1][point2d_idx];
      EXPECT_EQ(observed_id, point_id);
      // The observation is the exact, unoccluded projection of the point.
      const VirtualCamera& camera = cameras[image_id - 1];
      Eigen::Vector3d ray;
      ASSERT_TRUE(RayFromImage(camera.model_id, camera.params, pixel, &ray));
      const Eigen::Vector3d ray_in_world = camera.cam_from_world_rotation.conjugate() * ray;
      const Eigen::Vector3d point(x, y, z);
      const double distance = (point - camera.CentreInWorld()).norm();
      RayHit hit;
      ASSERT_TRUE(scene.CastRay(camera.CentreInWorld(), ray_in_world.normalized(), &hit));
      EXPECT_NEAR(hit.range, distance, 1e-6);
      EXPECT_LT((hit.point - point).norm(), 1e-6);
    }
    EXPECT_GE(track_length, 2);
  }

  // rig.txt reads back to the same cameras.
  std::vector<VirtualCamera> read;
  ASSERT_EQ(ReadRigFile((dir / "rig.txt").string(), ".jpg", &read), "");
  ASSERT_EQ(read.size(), cameras.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].name, cameras[i].name);
    EXPECT_EQ(read[i].params, cameras[i].params);
    EXPECT_LT((read[i].CentreInWorld() - cameras[i].CentreInWorld()).norm(), 1e-12);
  }
  fs::remove_all(dir);
}

TEST(Dataset, RefusesANonEmptyDirectoryAndAcceptsAnEmptyOne) {
  const fs::path dir = FreshPath("refuse");
  fs::create_directories(dir);
  { std::ofstream(dir / "keep.txt") << "precious"; }
  const Scene scene(SceneOptions{});
  const std::string error =
      WriteDataset(dir.string(), scene, SmallCameras(), SmallOptions(), nullptr);
  EXPECT_NE(error.find("refusing to overwrite non-empty"), std::string::npos) << error;
  EXPECT_TRUE(fs::exists(dir / "keep.txt"));
  EXPECT_FALSE(fs::exists(dir / "images"));
  EXPECT_FALSE(fs::exists(dir.string() + ".tmp"));

  fs::remove(dir / "keep.txt");
  EXPECT_EQ(WriteDataset(dir.string(), scene, SmallCameras(), SmallOptions(), nullptr), "");
  EXPECT_TRUE(fs::exists(dir / "sparse_gt/images.txt"));
  fs::remove_all(dir);
}

TEST(Dataset, BadCamerasAreNamedAndNothingIsWritten) {
  const fs::path dir = FreshPath("bad");
  const Scene scene(SceneOptions{});
  std::vector<VirtualCamera> cameras = SmallCameras();
  cameras[1].params = {64, 31};
  std::string error = WriteDataset(dir.string(), scene, cameras, SmallOptions(), nullptr);
  EXPECT_NE(error.find("'b.png'"), std::string::npos) << error;
  cameras = SmallCameras();
  cameras[2].params.pop_back();
  error = WriteDataset(dir.string(), scene, cameras, SmallOptions(), nullptr);
  EXPECT_NE(error.find("'c.jpg'"), std::string::npos) << error;
  cameras = SmallCameras();
  cameras[0] = MakeCamera("inside_box.jpg", "EQUIRECTANGULAR", 64, 32, {64, 32},
                          Eigen::Matrix3d::Identity(), Eigen::Vector3d(1.6, 1.0, 1.5));
  error = WriteDataset(dir.string(), scene, cameras, SmallOptions(), nullptr);
  EXPECT_NE(error.find("'inside_box.jpg'"), std::string::npos) << error;
  EXPECT_NE(error.find("free space"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(dir));
  EXPECT_FALSE(fs::exists(dir.string() + ".tmp"));
}

TEST(RigFile, ParsesAnyMixOfModelsAndRejectsBadLines) {
  const fs::path dir = FreshPath("rig");
  fs::create_directories(dir);
  const fs::path good = dir / "good.txt";
  {
    std::ofstream file(good);
    file << "# comment\n"
         << "pano EQUIRECTANGULAR 2048 1024 2048 1024 | 1 0 0 0 0 0 0\n"
         << "\n"
         << "fish.png UNIFIED_OMNI 1024 1024 450 450 512 512 1 0 0 0 0 | 0 0 1 0 0.5 0 0  # yaw 180\n"
         << "persp PINHOLE 640 480 320 320 320 240 | 1 0 0 0 -0.2 0.1 0.3\n";
  }
  std::vector<VirtualCamera> cameras;
  ASSERT_EQ(ReadRigFile(good.string(), ".jpg", &cameras), "");
  ASSERT_EQ(cameras.size(), 3u);
  EXPECT_EQ(cameras[0].name, "pano.jpg");
  EXPECT_EQ(cameras[1].name, "fish.png");
  EXPECT_EQ(cameras[1].model_id, 64);
  EXPECT_LT((cameras[1].CentreInWorld() - Eigen::Vector3d(0.5, 0, 0)).norm(), 1e-12);
  EXPECT_LT((cameras[2].CentreInWorld() - Eigen::Vector3d(0.2, -0.1, -0.3)).norm(), 1e-12);

  const std::vector<std::pair<std::string, std::string>> bad_lines = {
      {"cam1 FOO 640 480 1 2 3 4 | 1 0 0 0 0 0 0", "unknown camera model 'FOO'"},
      {"cam2 PINHOLE 640 480 1 2 3 | 1 0 0 0 0 0 0", "cam2"},
      {"cam3 PINHOLE 640 -480 320 320 320 240 | 1 0 0 0 0 0 0", "cam3"},
      {"cam4 PINHOLE 640 480 320 320 320 240 | 1 0 0 0 0 0", "7 numbers"},
      {"cam5 PINHOLE 640 480 320 320 320 240", "expected"},
      {"cam6 EQUIRECTANGULAR 640 480 640 480 | 1 0 0 0 0 0 0", "cam6"},
  };
  for (const auto& [line, expected] : bad_lines) {
    const fs::path bad = dir / "bad.txt";
    { std::ofstream(bad) << "ok PINHOLE 64 48 32 32 32 24 | 1 0 0 0 0 0 0\n" << line << "\n"; }
    const std::string error = ReadRigFile(bad.string(), ".jpg", &cameras);
    EXPECT_NE(error.find(expected), std::string::npos) << line << " -> " << error;
    EXPECT_NE(error.find(":2:"), std::string::npos) << error;
  }
  fs::remove_all(dir);
}

TEST(Layout, DefaultLayoutsAreValid) {
  const Scene scene(SceneOptions{});
  for (const char* name : {"room9", "ring", "grid"}) {
    LayoutOptions options;
    options.layout = name;
    std::vector<VirtualCamera> cameras;
    ASSERT_EQ(MakeLayout(options, &cameras), "") << name;
    EXPECT_EQ(CheckCameras(scene, cameras), "") << name;
  }
  LayoutOptions room9;
  std::vector<VirtualCamera> cameras;
  ASSERT_EQ(MakeLayout(room9, &cameras), "");
  ASSERT_EQ(cameras.size(), 9u);
  EXPECT_EQ(cameras[0].model_name, "EQUIRECTANGULAR");
  EXPECT_EQ(cameras[0].width, 2048);
  // 1.5 m above the floor (y = 1.5), 1 m grid spacing.
  EXPECT_NEAR(cameras[4].CentreInWorld().y(), 0.0, 1e-12);
  EXPECT_NEAR((cameras[1].CentreInWorld() - cameras[0].CentreInWorld()).norm(), 1.0, 1e-12);
  LayoutOptions ring;
  ring.layout = "ring";
  ASSERT_EQ(MakeLayout(ring, &cameras), "");
  EXPECT_EQ(cameras.size(), 16u);
  EXPECT_EQ(cameras[0].model_name, "PINHOLE");
  LayoutOptions bad;
  bad.layout = "spiral";
  EXPECT_NE(MakeLayout(bad, &cameras).find("spiral"), std::string::npos);
  bad.layout = "room9";
  bad.model_name = "NOPE";
  EXPECT_NE(MakeLayout(bad, &cameras).find("NOPE"), std::string::npos);
}

int RunRender(const std::string& args) {
  const std::string command = std::string(SPHERA_RENDER_EXE) + " " + args + " >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Program, ExitCodes) {
  const fs::path dir = FreshPath("cli");
  EXPECT_EQ(RunRender("--output " + dir.string() + " --model BOGUS"), 1);
  EXPECT_EQ(RunRender("--output " + dir.string() + " --model PINHOLE --width 64 --height 48 "
                      "--camera_params 1,2,3"),
            1);
  EXPECT_EQ(RunRender("--output " + dir.string() + " --supersample 0"), 1);
  EXPECT_EQ(RunRender("--bogus_flag 3"), 1);
  EXPECT_FALSE(fs::exists(dir));
  EXPECT_EQ(RunRender("--output " + dir.string() +
                      " --layout grid --num_cameras 2 --width 64 --height 32 --supersample 1 "
                      "--points 10 --noise_sigma 1"),
            0);
  EXPECT_TRUE(fs::exists(dir / "images/cam001.jpg"));
  EXPECT_EQ(DataLines(dir / "sparse_gt/images.txt").size(), 4u);
  // A second run into the now non-empty directory is refused.
  EXPECT_EQ(RunRender("--output " + dir.string() + " --layout grid --num_cameras 2 --width 64 "
                      "--height 32 --supersample 1"),
            1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace synthetic
}  // namespace sphera
