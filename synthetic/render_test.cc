#include "synthetic/render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "camera_models/registry.h"
#include "synthetic/file_formats.h"

namespace sphera {
namespace synthetic {
namespace {

constexpr double kDeg = M_PI / 180;

Eigen::Matrix3d WorldFromCam(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

double Cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

struct CornerStats {
  int num_corners = 0;
  double max_error_px = 0;
  double mean_error_px = 0;
  double max_off_axis_deg = 0;  // largest angle between a measured corner's ray and the optical axis
};

// Renders a checker room through `camera`, predicts every checker corner's
// pixel with ImageFromRay and measures it in the image with cornerSubPix,
// started 0.6 px away from the prediction. OpenCV puts pixel centres at
// integers, COLMAP at +0.5: a renderer off by half a pixel fails here.
CornerStats MeasureCheckerCorners(const VirtualCamera& camera, int supersample) {
  SceneOptions scene_options;
  scene_options.texture = TextureKind::kChecker;
  scene_options.with_boxes = false;
  scene_options.checker_size_m = 0.4;
  const Scene scene(scene_options);
  EXPECT_EQ(camera.Check(), "");
  RenderOptions options;
  options.supersample = supersample;
  const RenderedImage rendered = Render(scene, camera, options);
  cv::Mat gray;
  cv::cvtColor(rendered.image, gray, cv::COLOR_BGR2GRAY);
  gray.convertTo(gray, CV_32F);
  // A light blur makes the sampled gradient field smooth, which cornerSubPix
  // needs for ~0.03 px accuracy; it is symmetric, so it moves no corner.
  cv::GaussianBlur(gray, gray, cv::Size(0, 0), 1.0);

  const Eigen::Vector3d centre = camera.CentreInWorld();
  const double s = scene_options.checker_size_m;
  const double margin_m = 0.5;  // stay clear of the room's edges
  auto project = [&](const Eigen::Vector3d& point, Eigen::Vector2d* pixel) {
    const Eigen::Vector3d ray_in_cam =
        camera.cam_from_world_rotation * (point - centre).normalized();
    if (!ImageFromRay(camera.model_id, camera.params, ray_in_cam, pixel)) return false;
    Eigen::Vector3d back;
    return RayFromImage(camera.model_id, camera.params, *pixel, &back);
  };

  CornerStats stats;
  const int window = 4;  // cornerSubPix half window: 9 x 9 pixels
  for (int f = 0; f < static_cast<int>(scene.Faces().size()); ++f) {
    const Face& face = scene.Faces()[f];
    for (double u = std::ceil((face.min_uv.x() + margin_m) / s) * s;
         u <= face.max_uv.x() - margin_m; u += s) {
      for (double v = std::ceil((face.min_uv.y() + margin_m) / s) * s;
           v <= face.max_uv.y() - margin_m; v += s) {
        const Eigen::Vector3d corner = face.PointFromUV(Eigen::Vector2d(u, v));
        Eigen::Vector2d predicted;
        if (!project(corner, &predicted)) continue;
        // Near the poles of an equirectangular image a plane is imaged far
        // from affinely at the window's scale, which biases cornerSubPix
        // (not the renderer): measure only up to 60 degrees of elevation.
        if (camera.model_name == "EQUIRECTANGULAR" &&
            std::abs((camera.cam_from_world_rotation * (corner - centre)).normalized().y()) >
                std::sin(60 * kDeg)) {
          continue;
        }
        const double border = 2 * window + 4;
        if (predicted.x() < border || predicted.y() < border ||
            predicted.x() > camera.width - border || predicted.y() > camera.height - border) {
          continue;
        }
        // Squares must span well beyond the search window.
        bool large_enough = true;
        for (const Eigen::Vector2d& step : {Eigen::Vector2d(s, 0), Eigen::Vector2d(-s, 0),
                                            Eigen::Vector2d(0, s), Eigen::Vector2d(0, -s)}) {
          Eigen::Vector2d neighbour;
          large_enough = large_enough &&
                         project(face.PointFromUV(Eigen::Vector2d(u, v) + step), &neighbour) &&
                         (neighbour - predicted).norm() > 4 * window;
        }
        if (!large_enough) continue;
        // cornerSubPix assumes straight edges through the corner: skip
        // corners whose edges bend by more than 0.1 px across the search
        // window (e.g. near the poles of an equirectangular image).
        bool straight = true;
        for (const Eigen::Vector2d& direction : {Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 1)}) {
          Eigen::Vector2d forward, backward;
          if (!project(face.PointFromUV(Eigen::Vector2d(u, v) + s / 2 * direction), &forward) ||
              !project(face.PointFromUV(Eigen::Vector2d(u, v) - s / 2 * direction), &backward)) {
            straight = false;
            break;
          }
          const double step = s * window / (forward - backward).norm();  // ~window px
          straight = straight &&
                     project(face.PointFromUV(Eigen::Vector2d(u, v) + step * direction), &forward) &&
                     project(face.PointFromUV(Eigen::Vector2d(u, v) - step * direction), &backward) &&
                     std::abs(Cross2(forward + backward - 2 * predicted,
                                     (forward - backward).normalized())) < 0.1;
        }
        if (!straight) continue;
        // ... and a locally affine image of the face: the diagonal neighbour
        // ~window px away lands where the two edge steps predict.
        {
          Eigen::Vector2d along_u, along_v, diagonal;
          if (!project(face.PointFromUV(Eigen::Vector2d(u + s, v)), &along_u) ||
              !project(face.PointFromUV(Eigen::Vector2d(u, v + s)), &along_v)) {
            continue;
          }
          // Steps of ~window px along each edge.
          const double step_u = s * window / (along_u - predicted).norm();
          const double step_v = s * window / (along_v - predicted).norm();
          if (!project(face.PointFromUV(Eigen::Vector2d(u + step_u, v)), &along_u) ||
              !project(face.PointFromUV(Eigen::Vector2d(u, v + step_v)), &along_v) ||
              !project(face.PointFromUV(Eigen::Vector2d(u + step_u, v + step_v)), &diagonal) ||
              (diagonal - along_u - along_v + predicted).norm() > 0.15) {
            continue;
          }
        }
        std::vector<cv::Point2f> points = {cv::Point2f(static_cast<float>(predicted.x() - 0.5 + 0.6),
                                                       static_cast<float>(predicted.y() - 0.5 - 0.4))};
        cv::cornerSubPix(gray, points, cv::Size(window, window), cv::Size(-1, -1),
                         cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100,
                                          1e-4));
        const Eigen::Vector2d measured(points[0].x + 0.5, points[0].y + 0.5);
        const double error = (measured - predicted).norm();
        stats.max_error_px = std::max(stats.max_error_px, error);
        const Eigen::Vector3d ray_in_cam =
            camera.cam_from_world_rotation * (corner - centre).normalized();
        stats.max_off_axis_deg =
            std::max(stats.max_off_axis_deg, std::acos(std::clamp(ray_in_cam.z(), -1.0, 1.0)) / kDeg);
        stats.mean_error_px += error;
        ++stats.num_corners;
      }
    }
  }
  if (stats.num_corners > 0) stats.mean_error_px /= stats.num_corners;
  return stats;
}

struct CornerCase {
  const char* label;
  const char* model;
  int width, height;
  std::vector<double> params;
  Eigen::Vector3d centre;
  double yaw_deg, pitch_deg, roll_deg;
  int min_corners;
  double min_off_axis_deg;  // the measured corners must reach this far off-axis
};

class CheckerCornerTest : public ::testing::TestWithParam<CornerCase> {};

TEST_P(CheckerCornerTest, CornersLandWhereTheModelProjectsThem) {
  const CornerCase& c = GetParam();
  const VirtualCamera camera =
      MakeCamera(std::string(c.label) + ".png", c.model, c.width, c.height, c.params,
                 WorldFromCam(c.yaw_deg * kDeg, c.pitch_deg * kDeg, c.roll_deg * kDeg),
                 c.centre);
  const CornerStats stats = MeasureCheckerCorners(camera, 5);
  std::printf("%s: %d corners up to %.0f deg off-axis, mean error %.3f px, max %.3f px\n",
              c.label, stats.num_corners, stats.max_off_axis_deg, stats.mean_error_px,
              stats.max_error_px);
  EXPECT_GE(stats.num_corners, c.min_corners);
  EXPECT_GE(stats.max_off_axis_deg, c.min_off_axis_deg);
  EXPECT_LT(stats.max_error_px, 0.2);
  EXPECT_LT(stats.mean_error_px, 0.06);
}

INSTANTIATE_TEST_SUITE_P(
    AllModels, CheckerCornerTest,
    ::testing::Values(
        CornerCase{"pinhole", "PINHOLE", 320, 240, {200, 210, 161.3, 118.7},
                   Eigen::Vector3d(0.2, -0.1, 0.3), 12, 6, 3, 6, 25},
        CornerCase{"opencv", "OPENCV", 320, 240,
                   {200, 200, 158.2, 121.9, -0.12, 0.02, 0.001, -0.0015},
                   Eigen::Vector3d(-0.3, 0.2, 0.1), -20, -8, -4, 6, 25},
        CornerCase{"equirectangular", "EQUIRECTANGULAR", 1024, 512, {1024, 512},
                   Eigen::Vector3d(0.15, 0.1, -0.2), 30, 4, -3, 30, 150},
        // A 190 degree fisheye (95 degrees off-axis at 0.48 * 384 px).
        CornerCase{"unified_omni_190", "UNIFIED_OMNI", 384, 384,
                   {169, 169, 191.7, 193.1, 1.0, -0.04, 0.004, 0.0005, -0.0003},
                   Eigen::Vector3d(0.3, 0.2, -0.5), 25, -10, 5, 15, 85},
        CornerCase{"eucm", "EUCM", 384, 384, {104, 104, 192.5, 191.5, 0.6, 1.1},
                   Eigen::Vector3d(-0.2, 0.0, 0.4), 100, 5, 0, 15, 80},
        CornerCase{"double_sphere", "DOUBLE_SPHERE", 384, 384, {94, 94, 190, 194, -0.2, 0.6},
                   Eigen::Vector3d(0.4, -0.3, -0.4), 200, 0, 10, 15, 80}),
    [](const ::testing::TestParamInfo<CornerCase>& info) { return std::string(info.param.label); });

// Ranges measured independently with the pinhole formula: a pixel centre
// (u, v) looks along ((u - cx) / f, (v - cy) / f, 1).
TEST(Render, DepthIsTheRangeToTheKnownWall) {
  const Scene scene(SceneOptions{});
  const int width = 257, height = 201;
  const double f = 150, cx = 128.5, cy = 100.5;
  const Eigen::Vector3d centre(0.3, -0.2, 0.5);
  const VirtualCamera camera = MakeCamera("depth.png", "PINHOLE", width, height, {f, f, cx, cy},
                                          Eigen::Matrix3d::Identity(), centre);
  RenderOptions options;
  options.supersample = 2;
  const RenderedImage rendered = Render(scene, camera, options);
  // Centre pixel (128, 100) looks straight at the front wall z = 2.
  EXPECT_NEAR(rendered.depth.at<float>(100, 128), 1.5, 1e-6);
  int checked = 0;
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const Eigen::Vector3d ray((col + 0.5 - cx) / f, (row + 0.5 - cy) / f, 1.0);
      const double range = (2.0 - centre.z()) * ray.norm();
      const Eigen::Vector3d wall_point = centre + (2.0 - centre.z()) * ray;
      // Keep to the part of the wall no box hides from this camera.
      if (wall_point.x() < -1.5 || wall_point.x() > 1.0 || wall_point.y() < -1.4 ||
          wall_point.y() > 0.4) {
        continue;
      }
      ASSERT_NEAR(rendered.depth.at<float>(row, col), range, 2e-6 * range)
          << "pixel " << col << ", " << row;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20000);
}

TEST(Render, DepthSeesTheBoxInFrontOfTheWall) {
  const Scene scene(SceneOptions{});
  const double f = 150, cx = 128.5, cy = 100.5;
  const VirtualCamera camera =
      MakeCamera("box.png", "PINHOLE", 257, 201, {f, f, cx, cy}, Eigen::Matrix3d::Identity(),
                 Eigen::Vector3d(1.6, 0.3, 0.0));
  RenderOptions options;
  options.supersample = 1;
  const RenderedImage rendered = Render(scene, camera, options);
  // Pixel (128, 175) looks along (0, 0.5, 1) and meets the cabinet's front
  // face z = 1.2 at y = 0.9, inside its extent y in [0.6, 1.5].
  EXPECT_NEAR(rendered.depth.at<float>(175, 128), 1.2 * std::sqrt(1.25), 1e-6);
  // Pixel (128, 40) passes above the cabinet to the wall z = 2.
  const double ray_y = (40.5 - cy) / f;
  EXPECT_NEAR(rendered.depth.at<float>(40, 128), 2.0 * std::sqrt(1 + ray_y * ray_y), 1e-6);
}

TEST(Render, OutsideTheDomainIsBlackWithZeroDepth) {
  const Scene scene(SceneOptions{});
  // Double sphere with alpha > 0.5 has a bounded image disk.
  const VirtualCamera camera =
      MakeCamera("ds.png", "DOUBLE_SPHERE", 200, 200, {40, 40, 100, 100, -0.2, 0.6},
                 Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  ASSERT_EQ(camera.Check(), "");
  RenderOptions options;
  options.supersample = 2;
  const RenderedImage rendered = Render(scene, camera, options);
  Eigen::Vector3d ray;
  ASSERT_FALSE(RayFromImage(camera.model_id, camera.params, Eigen::Vector2d(0.5, 0.5), &ray));
  EXPECT_EQ(rendered.image.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(rendered.depth.at<float>(0, 0), 0.0f);
  EXPECT_GT(rendered.depth.at<float>(100, 100), 1.0f);
}

TEST(Render, EquirectangularDepthLiesOnTheSurfaces) {
  const Scene scene(SceneOptions{});
  const VirtualCamera camera =
      MakeCamera("pano.png", "EQUIRECTANGULAR", 128, 64, {128, 64},
                 WorldFromCam(0.3, 0.1, 0.05), Eigen::Vector3d(-0.4, 0.1, 0.6));
  RenderOptions options;
  options.supersample = 1;
  const RenderedImage rendered = Render(scene, camera, options);
  const Eigen::Matrix3d world_from_cam = camera.cam_from_world_rotation.conjugate().toRotationMatrix();
  for (int row = 0; row < 64; ++row) {
    for (int col = 0; col < 128; ++col) {
      Eigen::Vector3d ray;
      ASSERT_TRUE(RayFromImage(camera.model_id, camera.params,
                               Eigen::Vector2d(col + 0.5, row + 0.5), &ray));
      const Eigen::Vector3d point =
          camera.CentreInWorld() + rendered.depth.at<float>(row, col) * (world_from_cam * ray);
      double closest = 1e9;
      for (const Face& face : scene.Faces()) {
        closest = std::min(closest, std::abs(point[face.axis] - face.offset));
      }
      ASSERT_LT(closest, 1e-5) << col << ", " << row;
    }
  }
}

TEST(Render, DepthFileRoundTrip) {
  cv::Mat depth(3, 5, CV_32F);
  for (int i = 0; i < 15; ++i) depth.at<float>(i / 5, i % 5) = 0.25f * i;
  const std::string path = ::testing::TempDir() + "/sphera_depth_roundtrip.bin";
  ASSERT_TRUE(WriteDepthMap(path, depth));
  RangeMap read;
  ASSERT_EQ(ReadRangeMap(path, &read), "");
  ASSERT_EQ(read.height, 3);
  ASSERT_EQ(read.width, 5);
  for (int i = 0; i < 15; ++i) {
    EXPECT_EQ(read.At(i % 5, i / 5), depth.at<float>(i / 5, i % 5)) << i;
  }
  // Header: int32 width then height.
  std::FILE* file = std::fopen(path.c_str(), "rb");
  ASSERT_NE(file, nullptr);
  int32_t header[2];
  ASSERT_EQ(std::fread(header, sizeof(int32_t), 2, file), 2u);
  std::fclose(file);
  EXPECT_EQ(header[0], 5);
  EXPECT_EQ(header[1], 3);
  std::remove(path.c_str());
}

// Every way a range-map file can be damaged is refused with its reason.
TEST(Render, DamagedRangeMapsAreRefused) {
  const std::string path = ::testing::TempDir() + "/sphera_damaged_range.bin";
  const auto refusal = [&](const RangeMap& map, size_t keep_bytes, const std::string& extra) {
    EXPECT_TRUE(WriteRangeMap(path, map));
    std::string bytes;
    {
      std::ifstream in(path, std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    bytes = bytes.substr(0, std::min(keep_bytes, bytes.size())) + extra;
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    RangeMap read;
    return ReadRangeMap(path, &read);
  };
  RangeMap map;
  map.width = 2;
  map.height = 2;
  map.ranges = {1.0f, 0.0f, 2.5f, 3.0f};
  EXPECT_EQ(refusal(map, 1000, ""), "");
  EXPECT_NE(refusal(map, 4, "").find("header"), std::string::npos);
  EXPECT_NE(refusal(map, 20, "").find("fewer than its 4 ranges"), std::string::npos);
  EXPECT_NE(refusal(map, 1000, "x").find("more bytes"), std::string::npos);
  RangeMap nan = map;
  nan.ranges[3] = std::nanf("");
  EXPECT_NE(refusal(nan, 1000, "").find("at pixel (1, 1)"), std::string::npos);
  RangeMap negative = map;
  negative.ranges[1] = -1.0f;
  EXPECT_NE(refusal(negative, 1000, "").find("at pixel (1, 0)"), std::string::npos);
  RangeMap huge = map;
  huge.width = 70000;
  EXPECT_NE(refusal(huge, 1000, "").find("size 70000x2"), std::string::npos);
  RangeMap missing;
  EXPECT_EQ(ReadRangeMap(path + ".absent", &missing), "cannot be read");
  std::remove(path.c_str());
}

// Image files are told apart by their names in any letter case.
TEST(Render, ImageFileNames) {
  EXPECT_TRUE(IsJpegFileName("a/B.JPG"));
  EXPECT_TRUE(IsJpegFileName("frame.insp"));
  EXPECT_FALSE(IsJpegFileName("x.jpg/png"));
  EXPECT_TRUE(IsPngFileName("mask.Png"));
  EXPECT_TRUE(IsImageFileName("raw.TIFF"));
  EXPECT_FALSE(IsImageFileName("notes.txt"));
  EXPECT_FALSE(IsImageFileName("dir.jpg/file"));
  EXPECT_EQ(ImageWriteParams("x.bmp", 80), std::vector<int>{});
  EXPECT_EQ(ImageWriteParams("x.png", 80), (std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, 3}));
}

}  // namespace
}  // namespace synthetic
}  // namespace sphera
