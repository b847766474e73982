#include "colmap_ext/controllers/sphere_undistortion.h"

#include "colmap/image/undistortion.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/util/logging.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

namespace colmap {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;

Camera EquirectCamera(const int width, const camera_t camera_id = 1) {
  Camera camera;
  camera.camera_id = camera_id;
  camera.model_id = CameraModelId::kEquirectangular;
  camera.width = width;
  camera.height = width / 2;
  camera.params = {static_cast<double>(width), static_cast<double>(width / 2)};
  return camera;
}

Rigid3d PoseFromCenter(const Eigen::Quaterniond& rotation,
                       const Eigen::Vector3d& center) {
  return Rigid3d(rotation, -(rotation * center));
}

Eigen::Vector3d RandomUnit(std::mt19937* rng) {
  std::normal_distribution<double> normal;
  Eigen::Vector3d v(normal(*rng), normal(*rng), normal(*rng));
  return v.normalized();
}

class TempDir {
 public:
  TempDir() {
    std::string pattern =
        (fs::temp_directory_path() / "sphere_undistorter_test-XXXXXX")
            .string();
    path_ = mkdtemp(pattern.data());
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// Wraps a horizontal pixel difference on a panorama of the given width.
double WrappedDistance(const Eigen::Vector2d& a,
                       const Eigen::Vector2d& b,
                       const double width) {
  double dx = std::abs(a.x() - b.x());
  dx = std::min(dx, width - dx);
  return std::hypot(dx, a.y() - b.y());
}

TEST(SphereUndistorter, FaceRotationsAreCubeMapAxes) {
  // Expected viewing direction and image-down direction of each face, in
  // the camera frame (x right, y down, z forward).
  const std::map<CubeFace, std::pair<Eigen::Vector3d, Eigen::Vector3d>>
      expected = {
          {CubeFace::kFront, {{0, 0, 1}, {0, 1, 0}}},
          {CubeFace::kRight, {{1, 0, 0}, {0, 1, 0}}},
          {CubeFace::kBack, {{0, 0, -1}, {0, 1, 0}}},
          {CubeFace::kLeft, {{-1, 0, 0}, {0, 1, 0}}},
          {CubeFace::kUp, {{0, -1, 0}, {0, 0, 1}}},
          {CubeFace::kDown, {{0, 1, 0}, {0, 0, -1}}},
      };
  for (const auto& [face, axes] : expected) {
    const Eigen::Matrix3d R = FaceFromCamRotation(face);
    EXPECT_NEAR((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 0,
                1e-12)
        << CubeFaceName(face);
    EXPECT_NEAR(R.determinant(), 1, 1e-12) << CubeFaceName(face);
    EXPECT_NEAR((R * axes.first - Eigen::Vector3d(0, 0, 1)).norm(), 0, 1e-12)
        << CubeFaceName(face);
    EXPECT_NEAR((R * axes.second - Eigen::Vector3d(0, 1, 0)).norm(), 0,
                1e-12)
        << CubeFaceName(face);
  }
  // Horizontal faces: the right side of the front face continues into the
  // left side of the right face.
  const Eigen::Vector3d edge = Eigen::Vector3d(1, 0, 1).normalized();
  EXPECT_GT((FaceFromCamRotation(CubeFace::kFront) * edge).x(), 0);
  EXPECT_LT((FaceFromCamRotation(CubeFace::kRight) * edge).x(), 0);
}

TEST(SphereUndistorter, FacePoseComposition) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Quaterniond rotation(
        Eigen::AngleAxisd(1.0 + trial * 0.3, RandomUnit(&rng)));
    const Eigen::Vector3d center = 3 * RandomUnit(&rng);
    const Rigid3d cam_from_world = PoseFromCenter(rotation, center);
    for (const CubeFace face :
         {CubeFace::kFront, CubeFace::kRight, CubeFace::kBack,
          CubeFace::kLeft, CubeFace::kUp, CubeFace::kDown}) {
      const Rigid3d face_from_world =
          ViewFromWorld(FaceFromCamRotation(face), cam_from_world);
      // Same centre.
      const Eigen::Vector3d face_center =
          -(face_from_world.rotation().inverse() *
            face_from_world.translation());
      EXPECT_NEAR((face_center - center).norm(), 0, 1e-12);
      // Rotation = face_from_cam * cam_from_world.
      EXPECT_NEAR((face_from_world.rotation().toRotationMatrix() -
                   FaceFromCamRotation(face) * rotation.toRotationMatrix())
                      .norm(),
                  0, 1e-12);
      // Any world point: x_face = R_face (R x + t).
      const Eigen::Vector3d x = 5 * RandomUnit(&rng);
      EXPECT_NEAR((face_from_world * x -
                   FaceFromCamRotation(face) * (cam_from_world * x))
                      .norm(),
                  0, 1e-12);
    }
  }
}

TEST(SphereUndistorter, FaceCameraAndAutoSize) {
  const Camera face = MakeFaceCamera(512, 90);
  EXPECT_EQ(face.model_id, CameraModelId::kPinhole);
  EXPECT_EQ(face.width, 512);
  EXPECT_EQ(face.height, 512);
  EXPECT_NEAR(face.params[0], 256, 1e-9);
  EXPECT_NEAR(face.params[1], 256, 1e-9);
  EXPECT_NEAR(face.params[2], 256, 1e-12);
  EXPECT_NEAR(face.params[3], 256, 1e-12);
  EXPECT_NEAR(MakeFaceCamera(100, 60).params[0], 50 / std::tan(kPi / 6),
              1e-9);
  EXPECT_EQ(AutoFaceSize(EquirectCamera(2048), 90), 512);
  EXPECT_TRUE(IsCubeMappedModel(CameraModelId::kEquirectangular));
  EXPECT_TRUE(IsCubeMappedModel(UnifiedOmniCameraModel::model_id));
  EXPECT_TRUE(IsCubeMappedModel(CameraModelId::kOpenCVFisheye));
  EXPECT_FALSE(IsCubeMappedModel(CameraModelId::kOpenCV));
  EXPECT_FALSE(IsCubeMappedModel(CameraModelId::kPinhole));
}

// Every random 3D point around a panorama: its projection through the
// exported face camera (PINHOLE, face pose) is the face pixel whose remap
// source is the point's panorama pixel.
TEST(SphereUndistorter, FaceProjectionMatchesPanoramaRemap) {
  const Camera pano = EquirectCamera(2048);
  const Rigid3d cam_from_world = PoseFromCenter(
      Eigen::Quaterniond(Eigen::AngleAxisd(
          0.7, Eigen::Vector3d(0.3, 1, -0.2).normalized())),
      Eigen::Vector3d(0.4, -1.2, 2.0));
  const double fov = 95;  // 90 + 5 degrees of overlap
  const Camera face_camera = MakeFaceCamera(AutoFaceSize(pano, fov), fov);
  std::map<CubeFace, RemapMaps> maps;
  const std::vector<CubeFace> faces = {CubeFace::kFront, CubeFace::kRight,
                                       CubeFace::kBack,  CubeFace::kLeft,
                                       CubeFace::kUp,    CubeFace::kDown};
  for (const CubeFace face : faces) {
    maps[face] = BuildRemapMaps(pano, face_camera,
                                FaceFromCamRotation(face).transpose());
    EXPECT_EQ(maps[face].invalid_ratio, 0) << CubeFaceName(face);
  }

  std::mt19937 rng(11);
  std::uniform_real_distribution<double> distance(0.5, 20);
  const Eigen::Vector3d center =
      -(cam_from_world.rotation().inverse() * cam_from_world.translation());
  double max_geometric_error = 0;
  double max_map_error = 0;
  int num_checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d point = center + distance(rng) * RandomUnit(&rng);
    const std::optional<Eigen::Vector2d> projected_pano_pixel =
        pano.ImgFromCam(cam_from_world * point);
    ASSERT_TRUE(projected_pano_pixel.has_value());
    const Eigen::Vector2d pano_pixel = *projected_pano_pixel;
    int num_faces = 0;
    for (const CubeFace face : faces) {
      const Rigid3d face_from_world =
          ViewFromWorld(FaceFromCamRotation(face), cam_from_world);
      const std::optional<Eigen::Vector2d> projected_face_pixel =
          face_camera.ImgFromCam(face_from_world * point);
      if (!projected_face_pixel.has_value()) {
        continue;
      }
      const Eigen::Vector2d face_pixel = *projected_face_pixel;
      if (face_pixel.x() < 0 || face_pixel.y() < 0 ||
          face_pixel.x() >= face_camera.width ||
          face_pixel.y() >= face_camera.height) {
        continue;
      }
      ++num_faces;
      Eigen::Vector2d source_pixel;
      ASSERT_TRUE(ViewPixelToSourcePixel(pano, face_camera,
                                         FaceFromCamRotation(face).transpose(),
                                         face_pixel, &source_pixel));
      max_geometric_error =
          std::max(max_geometric_error,
                   WrappedDistance(source_pixel, pano_pixel, pano.width));

      // The cv::remap maps, bilinearly interpolated at the face pixel
      // (OpenCV pixel centres at integers), away from the seam where the
      // map jumps by the panorama width.
      const double u = face_pixel.x() - 0.5;
      const double v = face_pixel.y() - 0.5;
      const int u0 = static_cast<int>(std::floor(u));
      const int v0 = static_cast<int>(std::floor(v));
      if (u0 < 0 || v0 < 0 || u0 + 1 >= static_cast<int>(face_camera.width) ||
          v0 + 1 >= static_cast<int>(face_camera.height)) {
        continue;
      }
      const double a = u - u0;
      const double b = v - v0;
      auto interpolate = [&](const cv::Mat& map) {
        const double m00 = map.at<float>(v0, u0);
        const double m01 = map.at<float>(v0, u0 + 1);
        const double m10 = map.at<float>(v0 + 1, u0);
        const double m11 = map.at<float>(v0 + 1, u0 + 1);
        if (std::max({m00, m01, m10, m11}) - std::min({m00, m01, m10, m11}) >
            pano.width / 2.0) {
          return std::nan("");
        }
        return (1 - a) * (1 - b) * m00 + a * (1 - b) * m01 +
               (1 - a) * b * m10 + a * b * m11;
      };
      const double mx = interpolate(maps[face].map_x);
      const double my = interpolate(maps[face].map_y);
      if (std::isnan(mx) || std::isnan(my)) {
        continue;
      }
      max_map_error = std::max(
          max_map_error,
          WrappedDistance(Eigen::Vector2d(mx + 0.5, my + 0.5), pano_pixel,
                          pano.width));
      ++num_checked;
    }
    EXPECT_GE(num_faces, 1) << "point " << point.transpose()
                            << " is in no face";
  }
  EXPECT_GT(num_checked, 2000);
  EXPECT_LT(max_geometric_error, 1e-6);
  EXPECT_LT(max_map_error, 0.5);
}

// Resampling a smooth periodic panorama gives the function's value at the
// mapped source pixel on every face, also across the panorama seam.
TEST(SphereUndistorter, RemapImageSamplesAcrossTheSeam) {
  const Camera pano = EquirectCamera(512);
  auto value = [&](const double x, const double y) {  // COLMAP pixel coords
    return 128 + 60 * std::cos(2 * kPi * x / pano.width) +
           30 * std::sin(2 * kPi * 2 * x / pano.width) +
           20 * std::cos(kPi * y / pano.height);
  };
  cv::Mat image(pano.height, pano.width, CV_32FC1);
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      image.at<float>(row, col) = value(col + 0.5, row + 0.5);
    }
  }
  const Camera face = MakeFaceCamera(160, 100);
  // The cube faces, and the back face tilted so that the seam crosses it
  // obliquely (every face column then samples next to the seam somewhere).
  std::vector<std::pair<std::string, Eigen::Matrix3d>> views;
  for (const CubeFace f : {CubeFace::kFront, CubeFace::kBack,
                           CubeFace::kLeft, CubeFace::kUp}) {
    views.emplace_back(CubeFaceName(f), FaceFromCamRotation(f).transpose());
  }
  views.emplace_back(
      "tilted back",
      FaceFromCamRotation(CubeFace::kBack).transpose() *
          Eigen::AngleAxisd(0.3, Eigen::Vector3d(0, 0, 1)).toRotationMatrix());
  for (const auto& [view_name, cam_from_face] : views) {
    const cv::Mat remapped =
        RemapImage(image, pano, BuildRemapMaps(pano, face, cam_from_face));
    ASSERT_EQ(remapped.rows, 160);
    double max_error = 0;
    for (int row = 0; row < remapped.rows; ++row) {
      for (int col = 0; col < remapped.cols; ++col) {
        Eigen::Vector2d source_pixel;
        ASSERT_TRUE(ViewPixelToSourcePixel(pano, face, cam_from_face,
                                           Eigen::Vector2d(col + 0.5, row + 0.5),
                                           &source_pixel));
        // Near the poles the replicated border row differs from the
        // function; stay half a pixel away from them.
        if (source_pixel.y() < 1 || source_pixel.y() > pano.height - 1) {
          continue;
        }
        max_error = std::max(
            max_error, std::abs(remapped.at<float>(row, col) -
                                value(source_pixel.x(), source_pixel.y())));
      }
    }
    EXPECT_LT(max_error, 0.2) << view_name;
  }
}

TEST(SphereUndistorter, PerspectiveViewMatchesColmapUndistortion) {
  Camera camera = Camera::CreateFromModelId(1, CameraModelId::kOpenCV, 500,
                                            640, 480);
  camera.params = {500, 510, 322, 238, -0.12, 0.03, 0.001, -0.002};
  const Camera undistorted = UndistortCamera(UndistortCameraOptions(), camera);
  EXPECT_EQ(undistorted.model_id, CameraModelId::kPinhole);
  double max_error = 0;
  for (double y = 0.5; y < undistorted.height; y += 17) {
    for (double x = 0.5; x < undistorted.width; x += 13) {
      Eigen::Vector2d source_pixel;
      ASSERT_TRUE(ViewPixelToSourcePixel(camera, undistorted,
                                         Eigen::Matrix3d::Identity(),
                                         Eigen::Vector2d(x, y),
                                         &source_pixel));
      const std::optional<Eigen::Vector2d> cam_point =
          undistorted.CamFromImg(Eigen::Vector2d(x, y));
      ASSERT_TRUE(cam_point.has_value());
      const std::optional<Eigen::Vector2d> expected =
          camera.ImgFromCam(cam_point->homogeneous());
      ASSERT_TRUE(expected.has_value());
      max_error = std::max(max_error, (source_pixel - *expected).norm());
    }
  }
  EXPECT_LT(max_error, 1e-6);
}

TEST(SphereUndistorter, FisheyeFacesOutsideTheLensAreInvalid) {
  Camera fisheye = Camera::CreateFromModelId(
      1, CameraModelId::kOpenCVFisheye, 150, 400, 400);
  const Camera face = MakeFaceCamera(AutoFaceSize(fisheye, 90), 90);
  EXPECT_EQ(face.width, 300);
  const RemapMaps front = BuildRemapMaps(
      fisheye, face, FaceFromCamRotation(CubeFace::kFront).transpose());
  const RemapMaps back = BuildRemapMaps(
      fisheye, face, FaceFromCamRotation(CubeFace::kBack).transpose());
  const RemapMaps right = BuildRemapMaps(
      fisheye, face, FaceFromCamRotation(CubeFace::kRight).transpose());
  EXPECT_LT(front.invalid_ratio, 0.01);
  EXPECT_EQ(back.invalid_ratio, 1);
  EXPECT_GT(right.invalid_ratio, 0.5);
  EXPECT_LT(right.invalid_ratio, 0.95);
}

TEST(SphereUndistorter, BadOptionsAreNamed) {
  EXPECT_EQ(SphereUndistorterOptions().Check(), "");
  auto check = [](auto modify) {
    SphereUndistorterOptions options;
    modify(&options);
    return options.Check();
  };
  EXPECT_NE(check([](auto* o) { o->face_size = -1; }).find("face_size"),
            std::string::npos);
  EXPECT_NE(check([](auto* o) { o->face_size = 100000; }).find("face_size"),
            std::string::npos);
  EXPECT_EQ(check([](auto* o) { o->face_size = 16384; }), "");
  for (const double fov : {0.0, -10.0, 180.0, 200.0, std::nan("")}) {
    EXPECT_NE(check([&](auto* o) { o->fov_deg = fov; }).find("fov_deg"),
              std::string::npos)
        << fov;
  }
  EXPECT_NE(check([](auto* o) { o->overlap_deg = 95; }).find("overlap_deg"),
            std::string::npos);
  EXPECT_NE(check([](auto* o) { o->overlap_deg = -1; }).find("overlap_deg"),
            std::string::npos);
  const std::string unknown =
      check([](auto* o) { o->faces = "front,sideways"; });
  EXPECT_NE(unknown.find("faces"), std::string::npos);
  EXPECT_NE(unknown.find("sideways"), std::string::npos);
  EXPECT_NE(check([](auto* o) { o->faces = ""; }).find("faces"),
            std::string::npos);
  EXPECT_NE(check([](auto* o) { o->faces = "up,up"; }).find("faces"),
            std::string::npos);
  EXPECT_NE(check([](auto* o) { o->output_type = "PMVS"; })
                .find("output_type"),
            std::string::npos);
  EXPECT_NE(check([](auto* o) { o->image_format = "bmp"; })
                .find("image_format"),
            std::string::npos);
  EXPECT_NE(check([](auto* o) { o->max_invalid_ratio = 2; })
                .find("max_invalid_ratio"),
            std::string::npos);
  EXPECT_EQ(check([](auto* o) { o->faces = " front, up ,down"; }), "");
  // Names in any letter case, as COLMAP's enum options.
  EXPECT_EQ(check([](auto* o) {
              o->faces = "Front,UP";
              o->image_format = "PNG";
              o->output_type = "Colmap";
            }),
            "");
  ParsedSphereUndistorterOptions parsed;
  SphereUndistorterOptions upper;
  upper.image_format = "JPG";
  upper.faces = "BACK";
  ASSERT_EQ(upper.Parse(&parsed), "");
  EXPECT_EQ(parsed.image_format, SphereImageFormat::kJpg);
  ASSERT_EQ(parsed.faces.size(), 1);
  EXPECT_EQ(parsed.faces[0], CubeFace::kBack);

  std::vector<CubeFace> faces;
  EXPECT_EQ(ParseCubeFaces("front,right,back,left,up", &faces), "");
  EXPECT_EQ(faces.size(), 5);
  EXPECT_EQ(faces.back(), CubeFace::kUp);
}

// A tiny reconstruction of two panoramas showing sharp marker dots at known
// 3D points.
struct Scene {
  Reconstruction reconstruction;
  std::vector<Eigen::Vector3d> markers;
};

constexpr double kMarkerSigma = 0.025;  // radians

cv::Mat RenderPanorama(const Camera& camera,
                       const Rigid3d& cam_from_world,
                       const std::vector<Eigen::Vector3d>& markers) {
  std::vector<Eigen::Vector3d> directions;
  for (const Eigen::Vector3d& marker : markers) {
    directions.push_back((cam_from_world * marker).normalized());
  }
  cv::Mat image(camera.height, camera.width, CV_8UC1);
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      const std::optional<Eigen::Vector3d> pixel_ray =
          camera.CamRayFromImg(Eigen::Vector2d(col + 0.5, row + 0.5));
      EXPECT_TRUE(pixel_ray.has_value());
      const Eigen::Vector3d ray =
          pixel_ray.value_or(Eigen::Vector3d::UnitZ()).normalized();
      double value = 10;  // dark background
      for (const Eigen::Vector3d& direction : directions) {
        const double angle = std::acos(std::min(1.0, ray.dot(direction)));
        value += 240 * std::exp(-angle * angle /
                                (2 * kMarkerSigma * kMarkerSigma));
      }
      image.at<uint8_t>(row, col) =
          static_cast<uint8_t>(std::min(255.0, std::round(value)));
    }
  }
  return image;
}

Scene MakeScene(const fs::path& image_dir) {
  Scene scene;
  const Camera camera = EquirectCamera(512);
  scene.reconstruction.AddCameraWithTrivialRig(camera);
  const std::vector<Rigid3d> poses = {
      PoseFromCenter(Eigen::Quaterniond(Eigen::AngleAxisd(
                         0.4, Eigen::Vector3d(0.1, 1, 0.3).normalized())),
                     Eigen::Vector3d(0, 0, 0)),
      PoseFromCenter(Eigen::Quaterniond(Eigen::AngleAxisd(
                         -0.9, Eigen::Vector3d(-0.2, 1, 0).normalized())),
                     Eigen::Vector3d(0.6, 0.1, -0.3)),
  };
  // Markers: two per face of the first panorama, well inside the face, plus
  // one on the panorama seam (back face centre); at least 15 degrees apart.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> offset(-0.55, 0.55);
  std::uniform_real_distribution<double> depth(2, 5);
  std::vector<Eigen::Vector3d> rays_in_cam0 = {
      Eigen::Vector3d(0.01, 0.03, -1).normalized()};
  for (const CubeFace face :
       {CubeFace::kFront, CubeFace::kRight, CubeFace::kBack, CubeFace::kLeft,
        CubeFace::kUp, CubeFace::kDown}) {
    int added = 0;
    while (added < 2) {
      const Eigen::Vector3d ray_in_face =
          Eigen::Vector3d(offset(rng), offset(rng), 1).normalized();
      const Eigen::Vector3d ray =
          FaceFromCamRotation(face).transpose() * ray_in_face;
      bool far = true;
      for (const Eigen::Vector3d& other : rays_in_cam0) {
        far = far && std::acos(std::min(1.0, ray.dot(other))) > 0.26;
      }
      if (far) {
        rays_in_cam0.push_back(ray);
        ++added;
      }
    }
  }
  const Rigid3d world_from_cam0 = Inverse(poses[0]);
  for (const Eigen::Vector3d& ray : rays_in_cam0) {
    scene.markers.push_back(world_from_cam0 * (depth(rng) * ray));
  }

  std::vector<Track> tracks(scene.markers.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    Image image;
    image.SetImageId(i + 1);
    image.SetCameraId(camera.camera_id);
    image.SetName("pano" + std::to_string(i) + ".png");
    std::vector<Point2D> points2D;
    for (size_t j = 0; j < scene.markers.size(); ++j) {
      Point2D point2D;
      const std::optional<Eigen::Vector2d> xy =
          camera.ImgFromCam(poses[i] * scene.markers[j]);
      EXPECT_TRUE(xy.has_value());
      point2D.xy = xy.value_or(Eigen::Vector2d::Zero());
      point2D.point3D_id = j + 1;
      tracks[j].AddElement(i + 1, points2D.size());
      points2D.push_back(point2D);
    }
    // A keypoint without a 3D point.
    Point2D free_point;
    free_point.xy = Eigen::Vector2d(100.25, 140.75);
    points2D.push_back(free_point);
    image.SetPoints2D(points2D);
    // A trivial frame of the camera's trivial rig, registered at poses[i].
    scene.reconstruction.AddImageWithTrivialFrame(image, poses[i]);
    cv::imwrite((image_dir / image.Name()).string(),
                RenderPanorama(camera, poses[i], scene.markers));
  }
  for (size_t j = 0; j < scene.markers.size(); ++j) {
    Point3D point;
    point.xyz = scene.markers[j];
    point.color = Eigen::Vector3ub(250, 250, 250);
    point.error = 0.1;
    point.track = tracks[j];
    scene.reconstruction.AddPoint3D(j + 1, point);
  }
  return scene;
}

// Intensity-weighted centroid (COLMAP pixel convention) of the dot around
// `guess`; false when the window leaves the image.
bool DotCentroid(const cv::Mat& image,
                 const Eigen::Vector2d& guess,
                 Eigen::Vector2d* centroid) {
  const int radius = 7;
  const int cx = static_cast<int>(std::floor(guess.x()));
  const int cy = static_cast<int>(std::floor(guess.y()));
  if (cx - radius < 0 || cy - radius < 0 || cx + radius >= image.cols ||
      cy + radius >= image.rows) {
    return false;
  }
  double sum = 0;
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero();
  for (int y = cy - radius; y <= cy + radius; ++y) {
    for (int x = cx - radius; x <= cx + radius; ++x) {
      const double weight = std::max(0.0, image.at<uint8_t>(y, x) - 12.0);
      sum += weight;
      weighted += weight * Eigen::Vector2d(x + 0.5, y + 0.5);
    }
  }
  if (sum <= 0) {
    return false;
  }
  *centroid = weighted / sum;
  return true;
}

TEST(SphereUndistorter, EndToEndMarkersLandWhereTheModelSays) {
  TempDir temp;
  const fs::path image_dir = temp.path() / "images_in";
  fs::create_directories(image_dir);
  const Scene scene = MakeScene(image_dir);

  SphereUndistorterOptions options;
  options.image_format = "png";
  const fs::path output = temp.path() / "workspace";
  const SphereExportSummary summary = ExportPerspectiveWorkspace(
      scene.reconstruction, image_dir.string(), output.string(), options);
  EXPECT_EQ(summary.num_input_images, 2);
  EXPECT_EQ(summary.num_views, 12);
  EXPECT_EQ(summary.num_points3D, scene.markers.size());
  EXPECT_GT(summary.num_bytes, 0);

  // Layout: nothing left beside the output.
  for (const auto& entry : fs::directory_iterator(temp.path())) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"),
              std::string::npos)
        << entry.path();
  }
  for (const char* path :
       {"sparse/cameras.bin", "sparse/images.bin", "sparse/points3D.bin",
        "stereo/patch-match.cfg", "stereo/fusion.cfg", "stereo/depth_maps",
        "stereo/normal_maps", "stereo/consistency_graphs"}) {
    EXPECT_TRUE(fs::exists(output / path)) << path;
  }
  {
    std::ifstream cfg((output / "stereo/patch-match.cfg").string());
    std::string line;
    int num_lines = 0;
    int num_auto = 0;
    while (std::getline(cfg, line)) {
      ++num_lines;
      num_auto += line == "__auto__, 20";
    }
    EXPECT_EQ(num_lines, 24);
    EXPECT_EQ(num_auto, 12);
  }

  Reconstruction exported;
  exported.Read((output / "sparse").string());
  EXPECT_EQ(exported.NumCameras(), 1);
  EXPECT_EQ(exported.NumImages(), 12);
  EXPECT_EQ(exported.NumPoints3D(), scene.markers.size());
  const Camera& face_camera = exported.Camera(1);
  EXPECT_EQ(face_camera.model_id, CameraModelId::kPinhole);
  EXPECT_EQ(face_camera.width, 128);  // 512 / 4

  const Camera& pano_camera = scene.reconstruction.Camera(1);
  int num_dots = 0;
  int num_seam_dots = 0;
  double max_dot_error = 0;
  double max_projection_error = 0;
  for (const auto& [image_id, image] : exported.Images()) {
    const cv::Mat face_image = cv::imread(
        (output / "images" / image.Name()).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(face_image.empty()) << image.Name();
    ASSERT_EQ(face_image.cols, 128);
    for (const Point2D& point2D : image.Points2D()) {
      if (!point2D.HasPoint3D()) {
        continue;
      }
      // The model's observation is the projection of the 3D point.
      const std::optional<Eigen::Vector2d> projection = face_camera.ImgFromCam(
          image.CamFromWorld() * exported.Point3D(point2D.point3D_id).xyz);
      ASSERT_TRUE(projection.has_value());
      max_projection_error =
          std::max(max_projection_error, (*projection - point2D.xy).norm());
      // The image shows the dot there.
      Eigen::Vector2d centroid;
      if (DotCentroid(face_image, point2D.xy, &centroid)) {
        const double error = (centroid - point2D.xy).norm();
        EXPECT_LT(error, 0.5) << image.Name() << " point "
                              << point2D.point3D_id << " at "
                              << point2D.xy.transpose();
        max_dot_error = std::max(max_dot_error, error);
        ++num_dots;
        num_seam_dots += image.Name() == "pano0_back.png" &&
                         point2D.point3D_id == 1;
      }
    }
  }
  EXPECT_LT(max_projection_error, 1e-6);
  EXPECT_GE(num_dots, 20);
  EXPECT_EQ(num_seam_dots, 1);
  LOG(INFO) << "max dot centroid error " << max_dot_error << " px over "
            << num_dots << " dots";

  // Each observation is in exactly the faces that contain the point.
  const char* face_names[] = {"front", "right", "back",
                              "left",  "up",    "down"};
  for (const auto& [point3D_id, point] : exported.Points3D()) {
    std::set<std::string> observed;
    for (const TrackElement& element : point.track.Elements()) {
      observed.insert(exported.Image(element.image_id).Name());
    }
    std::set<std::string> expected;
    for (const auto& [source_id, source] :
         scene.reconstruction.Images()) {
      const Eigen::Vector3d ray =
          source.CamFromWorld() * scene.markers[point3D_id - 1];
      for (int f = 0; f < 6; ++f) {
        const Eigen::Vector3d in_face =
            FaceFromCamRotation(static_cast<CubeFace>(f)) * ray;
        if (in_face.z() > 0 && std::abs(in_face.x()) < in_face.z() &&
            std::abs(in_face.y()) < in_face.z()) {
          expected.insert(source.Name().substr(0, 5) + "_" + face_names[f] +
                          ".png");
        }
      }
    }
    EXPECT_EQ(observed, expected) << "point " << point3D_id;
    EXPECT_EQ(point.track.Length(), 2) << "point " << point3D_id;
  }
  (void)pano_camera;

  // A second export into the same folder is refused and leaves it intact.
  const size_t files_before = std::distance(
      fs::recursive_directory_iterator(output),
      fs::recursive_directory_iterator());
  try {
    ExportPerspectiveWorkspace(scene.reconstruction, image_dir.string(),
                               output.string(), options);
    ADD_FAILURE() << "exporting over a workspace succeeded";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("already holds a workspace"),
              std::string::npos)
        << error.what();
  }
  EXPECT_EQ(std::distance(fs::recursive_directory_iterator(output),
                          fs::recursive_directory_iterator()),
            files_before);
}

TEST(SphereUndistorter, SplattingLayoutAndFaceSubset) {
  TempDir temp;
  const fs::path image_dir = temp.path() / "images_in";
  fs::create_directories(image_dir);
  const Scene scene = MakeScene(image_dir);
  SphereUndistorterOptions options;
  options.splatting = true;
  options.faces = "front,right,back,left,up";
  options.face_size = 96;
  options.overlap_deg = 10;
  const fs::path output = temp.path() / "splat";
  fs::create_directories(output);  // an existing empty folder is fine
  const SphereExportSummary summary = ExportPerspectiveWorkspace(
      scene.reconstruction, image_dir.string(), output.string(), options);
  EXPECT_EQ(summary.num_views, 10);
  EXPECT_TRUE(fs::exists(output / "sparse/0/cameras.bin"));
  EXPECT_TRUE(fs::exists(output / "images/pano1_up.jpg"));
  EXPECT_FALSE(fs::exists(output / "images/pano1_down.jpg"));
  EXPECT_FALSE(fs::exists(output / "stereo"));
  Reconstruction exported;
  exported.Read((output / "sparse/0").string());
  EXPECT_EQ(exported.NumImages(), 10);
  for (const auto& [camera_id, camera] : exported.Cameras()) {
    EXPECT_EQ(camera.model_id, CameraModelId::kPinhole);
    EXPECT_EQ(camera.width, 96);
    EXPECT_NEAR(camera.params[0], 48 / std::tan(50 * kPi / 180), 1e-9);
  }
  // With 10 degrees of overlap, points near a face edge are in two faces.
  size_t num_observations = 0;
  for (const auto& [point3D_id, point] : exported.Points3D()) {
    num_observations += point.track.Length();
  }
  EXPECT_EQ(num_observations, summary.num_observations);
  EXPECT_GT(num_observations, exported.NumPoints3D());
}

// Two back-to-back 200-degree DOUBLE_SPHERE lenses 3 cm apart in one rig,
// two frames, with full masks: the per-frame export writes every direction
// around a frame from exactly one lens, the one nearer its axis; the
// per-lens export writes the lenses' overlap twice.
TEST(SphereUndistorter, PerFrameSharesTheDirectionsOfARigFrame) {
  TempDir temp;
  const fs::path image_dir = temp.path() / "images_in";
  const fs::path mask_dir = temp.path() / "masks_in";
  Reconstruction reconstruction;
  Rig rig;
  rig.SetRigId(1);
  for (camera_t camera_id : {1, 2}) {
    Camera camera;
    camera.camera_id = camera_id;
    camera.model_id = DoubleSphereCameraModel::model_id;
    camera.width = 128;
    camera.height = 128;
    camera.params = {29.5, 29.5, 64, 64, -0.2, 0.6};
    reconstruction.AddCamera(camera);
  }
  rig.AddRefSensor(sensor_t(SensorType::CAMERA, 1));
  // Lens 1 looks backwards (180 degrees about y), its centre 3 cm behind.
  const Eigen::Quaterniond back(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitY()));
  rig.AddSensor(sensor_t(SensorType::CAMERA, 2),
                PoseFromCenter(back, Eigen::Vector3d(0, 0, -0.03)));
  reconstruction.AddRig(rig);
  const std::vector<Rigid3d> rig_from_world = {
      PoseFromCenter(Eigen::Quaterniond(Eigen::AngleAxisd(
                         0.3, Eigen::Vector3d(0.2, 1, 0.1).normalized())),
                     Eigen::Vector3d(0.1, 0, 0.2)),
      PoseFromCenter(Eigen::Quaterniond(Eigen::AngleAxisd(
                         -0.7, Eigen::Vector3d(0, 1, 0.3).normalized())),
                     Eigen::Vector3d(0.5, -0.1, 0.4))};
  std::mt19937 rng(3);
  std::vector<Eigen::Vector3d> markers;
  for (int k = 0; k < 40; ++k) {
    markers.push_back(3 * RandomUnit(&rng));
  }
  for (size_t f = 0; f < rig_from_world.size(); ++f) {
    Frame frame;
    frame.SetFrameId(f + 1);
    frame.SetRigId(1);
    for (camera_t camera_id : {1, 2}) {
      frame.AddDataId(data_t(sensor_t(SensorType::CAMERA, camera_id),
                             2 * f + camera_id));
    }
    frame.SetRigFromWorld(rig_from_world[f]);
    reconstruction.AddFrame(frame);
    for (camera_t camera_id : {1, 2}) {
      Image image;
      image.SetImageId(2 * f + camera_id);
      image.SetCameraId(camera_id);
      image.SetFrameId(f + 1);
      const std::string lens = "lens" + std::to_string(camera_id - 1);
      image.SetName(lens + "/f" + std::to_string(f) + ".png");
      reconstruction.AddImage(image);
    }
    reconstruction.RegisterFrame(f + 1);
  }
  std::vector<Track> tracks(markers.size());
  for (const image_t image_id : reconstruction.RegImageIds()) {
    Image& image = reconstruction.Image(image_id);
    const Camera& camera = reconstruction.Camera(image.CameraId());
    std::vector<Point2D> points2D;
    for (size_t j = 0; j < markers.size(); ++j) {
      const std::optional<Eigen::Vector2d> xy =
          camera.ImgFromCam(image.CamFromWorld() * markers[j]);
      if (xy.has_value() && xy->x() > 0 && xy->y() > 0 && xy->x() < 128 &&
          xy->y() < 128) {
        Point2D point2D;
        point2D.xy = *xy;
        tracks[j].AddElement(image_id, points2D.size());
        points2D.push_back(point2D);
      }
    }
    image.SetPoints2D(points2D);
    for (const fs::path& dir : {image_dir, mask_dir}) {
      fs::create_directories((dir / image.Name()).parent_path());
    }
    // Bright dots at the markers; beyond the model's valid radius, black.
    cv::Mat lens_image(128, 128, CV_8UC1, cv::Scalar(0));
    for (int row = 0; row < 128; ++row) {
      for (int col = 0; col < 128; ++col) {
        const std::optional<Eigen::Vector3d> ray =
            camera.CamRayFromImg(Eigen::Vector2d(col + 0.5, row + 0.5));
        if (!ray.has_value()) {
          continue;
        }
        double value = 10;
        for (const Eigen::Vector3d& marker : markers) {
          const double angle = std::acos(std::min(
              1.0,
              ray->normalized().dot(
                  (image.CamFromWorld() * marker).normalized())));
          value += 240 * std::exp(-angle * angle / (2 * 0.05 * 0.05));
        }
        lens_image.at<uint8_t>(row, col) =
            static_cast<uint8_t>(std::min(255.0, value));
      }
    }
    cv::imwrite((image_dir / image.Name()).string(), lens_image);
    cv::imwrite((mask_dir / (image.Name() + ".png")).string(),
                cv::Mat(128, 128, CV_8U, cv::Scalar(255)));
  }
  for (size_t j = 0; j < markers.size(); ++j) {
    Point3D point;
    point.xyz = markers[j];
    point.track = tracks[j];
    if (point.track.Length() > 0) {
      reconstruction.AddPoint3D(j + 1, point);
    }
  }
  ASSERT_GT(reconstruction.NumPoints3D(), 30);

  // For random directions around each frame (rig frame), the views of that
  // frame whose mask keeps the direction, and their lenses.
  struct Coverage {
    size_t once = 0, twice = 0, none = 0, wrong_lens = 0;
  };
  auto export_coverage = [&](const bool per_frame,
                             SphereExportSummary* summary) {
    SphereUndistorterOptions options;
    options.per_frame = per_frame;
    options.mask_path = mask_dir.string();
    options.face_size = 48;
    options.image_format = "png";
    const fs::path output =
        temp.path() / (per_frame ? "per_frame" : "per_lens");
    *summary = ExportPerspectiveWorkspace(
        reconstruction, image_dir.string(), output.string(), options);
    Reconstruction exported;
    exported.Read((output / "sparse").string());
    std::map<std::string, cv::Mat> masks;
    for (const auto& [view_id, view] : exported.Images()) {
      masks[view.Name()] =
          cv::imread((output / "masks" / (view.Name() + ".png")).string(),
                     cv::IMREAD_GRAYSCALE);
      EXPECT_FALSE(masks[view.Name()].empty()) << view.Name();
    }
    Coverage coverage;
    std::mt19937 sample_rng(11);
    for (size_t f = 0; f < rig_from_world.size(); ++f) {
      for (int k = 0; k < 3000; ++k) {
        const Eigen::Vector3d ray_in_rig = RandomUnit(&sample_rng);
        const Eigen::Vector3d ray_in_world =
            rig_from_world[f].rotation().inverse() * ray_in_rig;
        int seen = 0;
        for (const auto& [view_id, view] : exported.Images()) {
          if (view.Name().find("/f" + std::to_string(f) + "_") ==
              std::string::npos) {
            continue;
          }
          const Camera& camera = exported.Camera(view.CameraId());
          const Eigen::Vector3d ray_in_view =
              view.CamFromWorld().rotation() * ray_in_world;
          const std::optional<Eigen::Vector2d> xy =
              camera.ImgFromCam(ray_in_view);
          if (ray_in_view.z() <= 0 || !xy.has_value() || xy->x() < 0 ||
              xy->y() < 0 || xy->x() >= camera.width ||
              xy->y() >= camera.height) {
            continue;
          }
          const cv::Mat& mask = masks.at(view.Name());
          if (mask.empty() ||
              mask.at<uint8_t>(static_cast<int>(xy->y()),
                               static_cast<int>(xy->x())) == 0) {
            continue;
          }
          ++seen;
          // Lens 0 looks along +z of the rig, lens 1 along -z.
          const bool lens0 = view.Name().rfind("lens0/", 0) == 0;
          if ((lens0 ? ray_in_rig.z() : -ray_in_rig.z()) < -0.02) {
            ++coverage.wrong_lens;
          }
        }
        ++(seen == 0 ? coverage.none
                     : (seen == 1 ? coverage.once : coverage.twice));
      }
    }
    return coverage;
  };
  SphereExportSummary per_lens_summary, per_frame_summary;
  const Coverage per_lens = export_coverage(false, &per_lens_summary);
  const Coverage per_frame = export_coverage(true, &per_frame_summary);
  LOG(INFO) << "directions seen once/twice/never, wrong lens: per lens "
            << per_lens.once << "/" << per_lens.twice << "/" << per_lens.none
            << ", " << per_lens.wrong_lens << "; per frame " << per_frame.once
            << "/" << per_frame.twice << "/" << per_frame.none << ", "
            << per_frame.wrong_lens;
  // Per lens: the 200-degree lenses overlap in a 20-degree band around the
  // rig's equator (about 17% of the sphere), seen twice.
  EXPECT_GT(per_lens.twice, 600);
  EXPECT_LT(per_lens.none, 60);
  // Per frame: every direction once (up to pixels on a boundary), and from
  // the lens whose hemisphere it is in.
  EXPECT_LT(per_frame.twice, 60);
  EXPECT_LT(per_frame.none, 60);
  EXPECT_EQ(per_frame.wrong_lens, 0);
  EXPECT_LT(per_frame_summary.num_observations,
            per_lens_summary.num_observations);
  EXPECT_EQ(per_frame_summary.num_views, per_lens_summary.num_views);
}

TEST(SphereUndistorter, FailuresLeaveNothingBehind) {
  TempDir temp;
  const fs::path image_dir = temp.path() / "images_in";
  fs::create_directories(image_dir);
  const Scene scene = MakeScene(image_dir);
  const fs::path output = temp.path() / "out";

  auto expect_failure = [&](const SphereUndistorterOptions& options,
                            const std::string& needle) {
    try {
      ExportPerspectiveWorkspace(scene.reconstruction, image_dir.string(),
                                 output.string(), options);
      ADD_FAILURE() << "no failure, expected " << needle;
    } catch (const std::exception& error) {
      EXPECT_NE(std::string(error.what()).find(needle), std::string::npos)
          << error.what();
    }
    EXPECT_FALSE(fs::exists(output));
    for (const auto& entry : fs::directory_iterator(temp.path())) {
      EXPECT_EQ(entry.path().filename().string().find(".tmp-"),
                std::string::npos)
          << entry.path();
    }
  };

  SphereUndistorterOptions bad;
  bad.face_size = -4;
  expect_failure(bad, "face_size");
  bad = SphereUndistorterOptions();
  bad.faces = "front,top";
  expect_failure(bad, "top");

  // The second image is a PNG cut in half: named before anything is
  // written (a decoder would fill the missing half with gray).
  {
    const fs::path png = image_dir / "pano1.png";
    std::string bytes;
    {
      std::ifstream in(png.string(), std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    ASSERT_GT(bytes.size(), 100u);
    std::ofstream(png.string(), std::ios::binary | std::ios::trunc)
        << bytes.substr(0, bytes.size() / 2);
    expect_failure(SphereUndistorterOptions(), "image pano1.png: ");
  }

  // The second image is unreadable: the first one was already written
  // into the temporary folder, which must disappear.
  {
    std::ofstream corrupt((image_dir / "pano1.png").string(),
                          std::ios::trunc);
    corrupt << "not an image";
  }
  expect_failure(SphereUndistorterOptions(), "pano1.png");
  fs::remove(image_dir / "pano1.png");
  expect_failure(SphereUndistorterOptions(), "pano1.png");
}

}  // namespace
}  // namespace colmap
