#include "colmap_ext/controllers/sphere_bundle_adjustment.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/camera.h"
#include "colmap/scene/image.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/sfm/observation_manager.h"
#include "colmap_ext/exe/sphere_bundle_adjuster.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace colmap {
namespace {

using Options = SphereBundleAdjustmentOptions;

constexpr double kDeg = M_PI / 180;

Eigen::Vector3d RandomUnit(std::mt19937* rng) {
  std::normal_distribution<double> n(0, 1);
  return Eigen::Vector3d(n(*rng), n(*rng), n(*rng)).normalized();
}

// Sets an image's pose through its (trivial) frame.
void SetCamFromWorld(Reconstruction* rec,
                     const image_t image_id,
                     const Rigid3d& cam_from_world) {
  const Image& image = rec->Image(image_id);
  rec->Frame(image.FrameId()).SetCamFromWorld(image.CameraId(), cam_from_world);
}

// The paper's room: 9 equirectangular 2048 x 1024 cameras on a 3 x 3 grid in
// a 4 x 4 x 3 m room, random orientations, points on the walls. Optionally a
// PINHOLE camera (image 10) with a wrong focal length (hybrid set). Every
// camera has a trivial rig and every image a trivial frame.
Reconstruction MakeRoom(int num_points,
                        double noise_px,
                        double outlier_rate,
                        bool with_pinhole,
                        std::mt19937* rng,
                        Reconstruction* ground_truth) {
  Reconstruction rec;
  Camera equirect;
  equirect.camera_id = 1;
  equirect.model_id = CameraModelId::kEquirectangular;
  equirect.width = 2048;
  equirect.height = 1024;
  equirect.params = {2048, 1024};
  rec.AddCameraWithTrivialRig(equirect);
  Camera pinhole;
  pinhole.camera_id = 2;
  pinhole.model_id = CameraModelId::kPinhole;
  pinhole.width = 800;
  pinhole.height = 600;
  pinhole.params = {300, 300, 400, 300};
  if (with_pinhole) rec.AddCameraWithTrivialRig(pinhole);

  std::vector<Eigen::Vector3d> points;
  std::uniform_real_distribution<double> ux(-2, 2), uy(-1.5, 1.5);
  std::uniform_int_distribution<int> wall(0, 5);
  for (int j = 0; j < num_points; ++j) {
    Eigen::Vector3d X(ux(*rng), uy(*rng), ux(*rng));
    switch (wall(*rng)) {
      case 0: X.x() = -2; break;
      case 1: X.x() = 2; break;
      case 2: X.y() = -1.5; break;
      case 3: X.y() = 1.5; break;
      case 4: X.z() = -2; break;
      default: X.z() = 2; break;
    }
    points.push_back(X);
  }
  std::normal_distribution<double> noise(0, noise_px);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<std::vector<std::pair<image_t, point2D_t>>> tracks(num_points);
  const int num_images = with_pinhole ? 10 : 9;
  for (int i = 0; i < num_images; ++i) {
    Image image;
    image.SetImageId(i + 1);
    image.SetName("image" + std::to_string(i + 1) + ".png");
    const bool is_pinhole = i == 9;
    image.SetCameraId(is_pinhole ? 2 : 1);
    const Eigen::Vector3d center =
        is_pinhole ? Eigen::Vector3d(0.3, 0.2, 0.4)
                   : Eigen::Vector3d((i % 3) - 1.0, 0, (i / 3) - 1.0);
    // The pinhole looks into a corner of the room (several depths, so focal
    // length and distance to the wall are not confused).
    const Eigen::Quaterniond q =
        is_pinhole ? Eigen::Quaterniond(
                         Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitY()) *
                         Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
                   : Eigen::Quaterniond(
                         Eigen::AngleAxisd(M_PI * unit(*rng), RandomUnit(rng)));
    const Rigid3d cam_from_world(q, -(q * center));
    const Camera& camera = is_pinhole ? pinhole : equirect;
    std::vector<Eigen::Vector2d> xys;
    for (int j = 0; j < num_points; ++j) {
      const std::optional<Eigen::Vector2d> projected =
          camera.ImgFromCam(cam_from_world * points[j]);
      if (!projected.has_value()) {
        continue;
      }
      Eigen::Vector2d xy = *projected;
      if (xy.x() < 0 || xy.y() < 0 || xy.x() >= camera.width ||
          xy.y() >= camera.height) {
        continue;
      }
      xy += Eigen::Vector2d(noise(*rng), noise(*rng));
      if (unit(*rng) < outlier_rate) {
        xy += Eigen::Vector2d(40, -30);
      }
      if (!is_pinhole) {
        xy.x() = std::fmod(xy.x() + camera.width, camera.width);
        xy.y() = std::clamp(xy.y(), 0.0, camera.height - 1e-6);
      } else if (xy.x() < 0 || xy.y() < 0 || xy.x() >= camera.width ||
                 xy.y() >= camera.height) {
        continue;
      }
      tracks[j].emplace_back(i + 1, static_cast<point2D_t>(xys.size()));
      xys.push_back(xy);
    }
    image.SetPoints2D(xys);
    rec.AddImageWithTrivialFrame(image, cam_from_world);
  }
  for (int j = 0; j < num_points; ++j) {
    if (tracks[j].size() < 2) continue;
    Track track;
    for (const auto& [image_id, idx] : tracks[j]) {
      track.AddElement(image_id, idx);
    }
    rec.AddPoint3D(points[j], track);
  }
  if (ground_truth) *ground_truth = rec;
  // Perturb the poses (0.5 deg, 2 cm) and, with the pinhole, its focal.
  for (const image_t id : rec.RegImageIds()) {
    Rigid3d pose = rec.Image(id).CamFromWorld();
    const Eigen::Vector3d c =
        rec.Image(id).ProjectionCenter() + 0.02 * RandomUnit(rng);
    pose.rotation() =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * kDeg, RandomUnit(rng))) *
        pose.rotation();
    pose.translation() = -(pose.rotation() * c);
    SetCamFromWorld(&rec, id, pose);
  }
  if (with_pinhole) rec.Camera(2).params = {315, 315, 400, 300};
  return rec;
}

// Max rotation [deg] / position [m] errors after a similarity alignment on
// the camera centres (removes the gauge).
void PoseErrors(const Reconstruction& gt,
                const Reconstruction& est,
                double* rot_deg,
                double* pos_m) {
  std::vector<image_t> ids = gt.RegImageIds();
  std::sort(ids.begin(), ids.end());
  Eigen::Matrix3Xd src(3, ids.size()), dst(3, ids.size());
  for (size_t k = 0; k < ids.size(); ++k) {
    src.col(k) = est.Image(ids[k]).ProjectionCenter();
    dst.col(k) = gt.Image(ids[k]).ProjectionCenter();
  }
  const Eigen::Matrix4d S = Eigen::umeyama(src, dst, true);
  const double s = std::cbrt(S.block<3, 3>(0, 0).determinant());
  const Eigen::Matrix3d R = S.block<3, 3>(0, 0) / s;
  *rot_deg = 0;
  *pos_m = 0;
  for (size_t k = 0; k < ids.size(); ++k) {
    const Eigen::Vector3d c =
        S.block<3, 3>(0, 0) * src.col(k) + S.block<3, 1>(0, 3);
    *pos_m = std::max(*pos_m, (c - dst.col(k)).norm());
    const Eigen::Matrix3d R_est =
        est.Image(ids[k]).CamFromWorld().rotation().toRotationMatrix() *
        R.transpose();
    const Eigen::Matrix3d R_gt =
        gt.Image(ids[k]).CamFromWorld().rotation().toRotationMatrix();
    *rot_deg = std::max(
        *rot_deg, Eigen::AngleAxisd(R_gt.transpose() * R_est).angle() / kDeg);
  }
}

TEST(SphereBundleAdjustment, CameraOnlyNoiseFree) {
  std::mt19937 rng(1);
  Reconstruction gt;
  Reconstruction rec = MakeRoom(200, 0, 0, false, &rng, &gt);
  Options options;
  options.tau_px = 100;  // initial errors are ~1 deg = 6 px
  options.max_iterations = 10;
  SphereBundleAdjustmentSummary summary;
  std::string error;
  ASSERT_TRUE(SphereBundleAdjust(options, &rec, &summary, &error)) << error;
  double rot, pos;
  PoseErrors(gt, rec, &rot, &pos);
  EXPECT_LT(rot, 1e-6);
  EXPECT_LT(pos, 1e-7);
  EXPECT_EQ(summary.num_points_after, 200u);
  EXPECT_LT(summary.mean_error_after_px, 1e-5);
  EXPECT_GT(summary.mean_error_before_px, 1);
}

// The filter the mappers run before every global bundle adjustment: a point
// that sits at a spherical camera's centre (where the angular residual has no
// direction and its derivatives blow up) loses that observation; a point a
// centimetre from a camera in a 4 m room is kept, as is everything else.
TEST(SphereBundleAdjustment, PointAtACameraCentreIsFilteredBeforeAdjustment) {
  std::mt19937 rng(5);
  Reconstruction rec = MakeRoom(200, 0, 0, false, &rng, nullptr);
  const Image& image = rec.Image(1);
  std::vector<point2D_t> observed;
  for (point2D_t idx = 0; idx < image.NumPoints2D(); ++idx) {
    const Point2D& point2D = image.Point2D(idx);
    if (point2D.HasPoint3D() &&
        rec.Point3D(point2D.point3D_id).track.Length() >= 3) {
      observed.push_back(idx);
    }
  }
  ASSERT_GE(observed.size(), 2u);
  const point3D_t collapsed = image.Point2D(observed[0]).point3D_id;
  const point3D_t near = image.Point2D(observed[1]).point3D_id;
  const Eigen::Vector3d center = image.ProjectionCenter();
  rec.Point3D(collapsed).xyz =
      center + 1e-9 * (rec.Point3D(collapsed).xyz - center).normalized();
  rec.Point3D(near).xyz =
      center + 0.01 * (rec.Point3D(near).xyz - center).normalized();
  const size_t num_observations = rec.ComputeNumObservations();

  EXPECT_EQ(ObservationManager(rec).FilterObservationsWithNegativeDepth(), 1u);
  EXPECT_FALSE(rec.Image(1).Point2D(observed[0]).HasPoint3D());
  EXPECT_TRUE(rec.ExistsPoint3D(collapsed));
  EXPECT_TRUE(rec.Image(1).Point2D(observed[1]).HasPoint3D());
  EXPECT_EQ(rec.ComputeNumObservations(), num_observations - 1);
}

TEST(SphereBundleAdjustment, ModesWithNoiseAndOutliers) {
  for (const std::string mode : {"camera_only", "full_angular", "full_pixel"}) {
    std::mt19937 rng(2);
    Reconstruction gt;
    Reconstruction rec = MakeRoom(300, 0.5, 0.02, false, &rng, &gt);
    Options options;
    options.mode =
        mode == "camera_only" ? Options::Mode::CAMERA_ONLY : Options::Mode::FULL;
    options.residual = mode == "full_pixel" ? Options::Residual::PIXEL
                                            : Options::Residual::ANGULAR;
    SphereBundleAdjustmentSummary summary;
    std::string error;
    if (mode == "camera_only") {
      // Loose tau from the perturbed start, then tau = 3 px.
      options.tau_px = 30;
      options.max_iterations = 3;
      ASSERT_TRUE(SphereBundleAdjust(options, &rec, &summary, &error)) << error;
      options.tau_px = 3;
      options.max_iterations = 20;
    } else {
      options.loss = Options::Loss::CAUCHY;
    }
    ASSERT_TRUE(SphereBundleAdjust(options, &rec, &summary, &error))
        << mode << ": " << error;
    double rot, pos;
    PoseErrors(gt, rec, &rot, &pos);
    EXPECT_LT(rot, 0.05) << mode;
    EXPECT_LT(pos, 5e-3) << mode;
    EXPECT_GT(summary.iterations, 0) << mode;
    if (mode == "camera_only") {
      // Outlier observations (50 px) never end in a reliable point.
      EXPECT_LT(summary.num_points_after, 300u);
      EXPECT_GT(summary.num_points_after, 150u);
      EXPECT_LT(summary.mean_error_after_px, 1.0);
      for (const auto& [id, point] : rec.Points3D()) {
        EXPECT_LE(point.error, 3.0);
      }
    }
  }
}

TEST(SphereBundleAdjustment, HybridRefinesPinholeFocal) {
  std::mt19937 rng(3);
  Reconstruction gt;
  Reconstruction rec = MakeRoom(600, 0, 0, true, &rng, &gt);
  Options options;
  options.tau_px = 100;
  options.max_iterations = 30;
  options.refine_intrinsics = true;
  SphereBundleAdjustmentSummary summary;
  std::string error;
  ASSERT_TRUE(SphereBundleAdjust(options, &rec, &summary, &error)) << error;
  EXPECT_NEAR(rec.Camera(2).params[0], 300, 0.5);
  EXPECT_NEAR(rec.Camera(2).params[1], 300, 0.5);
  EXPECT_EQ(rec.Camera(2).params[2], 400);   // principal point kept
  EXPECT_EQ(rec.Camera(1).params[0], 2048);  // EQUIRECTANGULAR w, h fixed
  EXPECT_EQ(rec.Camera(1).params[1], 1024);
  double rot, pos;
  PoseErrors(gt, rec, &rot, &pos);
  EXPECT_LT(rot, 0.01);
}

TEST(SphereBundleAdjustment, BadInputIsReported) {
  std::mt19937 rng(4);
  const Reconstruction rec = MakeRoom(100, 0.5, 0, false, &rng, nullptr);
  auto run = [&](const Options& options, Reconstruction model) {
    SphereBundleAdjustmentSummary summary;
    std::string error;
    const Reconstruction before = model;
    EXPECT_FALSE(SphereBundleAdjust(options, &model, &summary, &error));
    // Unchanged on failure.
    for (const image_t id : before.RegImageIds()) {
      EXPECT_EQ(Eigen::Vector3d(model.Image(id).CamFromWorld().translation()),
                Eigen::Vector3d(before.Image(id).CamFromWorld().translation()));
    }
    EXPECT_EQ(model.NumPoints3D(), before.NumPoints3D());
    return error;
  };
  Options options;
  options.tau_px = 0;
  EXPECT_NE(run(options, rec).find("--tau_px"), std::string::npos);
  options.tau_px = -1;
  EXPECT_NE(run(options, rec).find("--tau_px"), std::string::npos);
  options.tau_px = 1e-4;  // below the noise floor
  const std::string floor_error = run(options, rec);
  EXPECT_NE(floor_error.find("noise floor"), std::string::npos) << floor_error;
  EXPECT_NE(floor_error.find("--tau_px"), std::string::npos) << floor_error;
  options.tau_px = 2;
  // A value outside the enum is refused by SphereBundleAdjust (a bad
  // spelling by the option manager, tests/bad_input_test.py).
  options.mode = static_cast<Options::Mode>(7);
  EXPECT_NE(run(options, rec).find("--mode"), std::string::npos);
  options.mode = Options::Mode::CAMERA_ONLY;
  options.residual = Options::Residual::PIXEL;
  EXPECT_NE(run(options, rec).find("--residual"), std::string::npos);
  options.residual = Options::Residual::ANGULAR;
  options.min_observations_per_image = 1000;
  const std::string few = run(options, rec);
  EXPECT_NE(few.find("too few observations"), std::string::npos) << few;
  EXPECT_NE(few.find("image1.png"), std::string::npos) << few;
  options.min_observations_per_image = 6;
  // Degenerate: the first two images at the same centre.
  Reconstruction degenerate = rec;
  Rigid3d pose2 = degenerate.Image(2).CamFromWorld();
  pose2.translation() =
      -(pose2.rotation() * degenerate.Image(1).ProjectionCenter());
  SetCamFromWorld(&degenerate, 2, pose2);
  const std::string deg = run(options, degenerate);
  EXPECT_NE(deg.find("degenerate"), std::string::npos) << deg;
}

TEST(SphereBundleAdjustment, CommandLineWritesOnlyOnSuccess) {
  std::mt19937 rng(5);
  Reconstruction gt;
  const Reconstruction rec = MakeRoom(150, 0.3, 0, false, &rng, &gt);
  const std::string dir = std::filesystem::temp_directory_path() /
                          ("sphere_ba_test_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const std::string input = dir + "/input";
  const std::string output = dir + "/output";
  std::filesystem::create_directories(input);
  rec.Write(input);
  const auto input_time =
      std::filesystem::last_write_time(input + "/images.bin");

  auto run = [](std::vector<std::string> args) {
    args.insert(args.begin(), "colmap");
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    return RunSphereBundleAdjuster(static_cast<int>(argv.size()),
                                   argv.data());
  };
  EXPECT_NE(run({"--input_path",
                 input,
                 "--output_path",
                 output,
                 "--tau_px",
                 "0.0001"}),
            EXIT_SUCCESS);
  EXPECT_FALSE(std::filesystem::exists(output));
  EXPECT_NE(
      run({"--input_path", input, "--output_path", output, "--tau_px", "0"}),
      EXIT_SUCCESS);
  EXPECT_FALSE(std::filesystem::exists(output));
  EXPECT_NE(run({"--input_path", dir + "/missing", "--output_path", output}),
            EXIT_SUCCESS);
  EXPECT_EQ(run({"--input_path",
                 input,
                 "--output_path",
                 output,
                 "--mode",
                 "camera_only",
                 "--tau_px",
                 "50",
                 "--max_iterations",
                 "5"}),
            EXIT_SUCCESS);
  ASSERT_TRUE(std::filesystem::exists(output + "/images.bin"));
  EXPECT_EQ(std::filesystem::last_write_time(input + "/images.bin"),
            input_time);
  Reconstruction written;
  written.Read(output);
  double rot, pos;
  PoseErrors(gt, written, &rot, &pos);
  EXPECT_LT(rot, 0.05);
  EXPECT_EQ(run({"--input_path",
                 input,
                 "--output_path",
                 dir + "/full",
                 "--mode",
                 "full",
                 "--residual",
                 "pixel"}),
            EXIT_SUCCESS);
  EXPECT_TRUE(std::filesystem::exists(dir + "/full/points3D.bin"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace colmap
