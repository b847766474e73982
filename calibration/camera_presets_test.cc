#include "calibration/camera_presets.h"

#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "camera_models/projection_check.h"
#include "camera_models/registry.h"

namespace sphera {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The message of what FUNC throws as std::invalid_argument ("" if nothing).
template <typename Func>
std::string ErrorOf(Func&& func) {
  try {
    func();
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "";
}

// Every known resolution of a preset, and for the generic dual fisheye two
// sizes of its own.
std::vector<PresetResolution> Resolutions(const CameraPreset& preset) {
  if (!preset.any_two_to_one_size) return preset.resolutions;
  return {FindPresetResolution(preset, 2048, 1024),
          FindPresetResolution(preset, "5760x2880")};
}

TEST(CameraPresets, NamesAreUniqueAndFoundInAnyCase) {
  std::set<std::string> names;
  for (const CameraPreset& preset : CameraPresets()) {
    EXPECT_TRUE(names.insert(preset.name).second) << preset.name;
    std::string upper = preset.name;
    for (char& c : upper) c = static_cast<char>(std::toupper(c));
    EXPECT_EQ(&FindCameraPreset(upper), &preset);
    EXPECT_FALSE(preset.description.empty());
    EXPECT_FALSE(preset.source.empty());
  }
  // The cameras the issue asks for.
  for (const char* name :
       {"ricoh_theta_s", "ricoh_theta_v", "ricoh_theta_z1", "ricoh_theta_x",
        "insta360_one_x2", "insta360_x3", "insta360_x4", "gopro_fusion",
        "gopro_max", "kandao_qoocam_8k", "kandao_qoocam_3", "vuze",
        "vuze_xr", "dual_fisheye"}) {
    EXPECT_EQ(names.count(name), 1u) << name;
  }
  const std::string error = ErrorOf([] { FindCameraPreset("theta"); });
  EXPECT_NE(error.find("\"theta\""), std::string::npos) << error;
  for (const std::string& name : names) {
    EXPECT_NE(error.find(name), std::string::npos) << error;
  }
  EXPECT_EQ(PresetListText().find("list"), std::string::npos);
  for (const std::string& name : names) {
    EXPECT_NE(PresetListText().find(name + ": "), std::string::npos);
  }
}

// The distance from the circle's centre of the pixel of a ray THETA off the
// axis along the image's longer axis, or infinity when it has none.
double RadiusOfRay(const PresetCamera& camera, const PresetCircle& circle,
                   double theta) {
  const bool wide = camera.width >= camera.height;
  const Eigen::Vector3d ray(wide ? std::sin(theta) : 0,
                            wide ? 0 : std::sin(theta), std::cos(theta));
  Eigen::Vector2d pixel;
  if (!ImageFromRay(camera.model_id, camera.params, ray, &pixel)) {
    return std::numeric_limits<double>::infinity();
  }
  return (pixel - Eigen::Vector2d(circle.cx, circle.cy)).norm();
}

TEST(CameraPresets, LensCamerasAreEachLensInOrder) {
  for (const CameraPreset& preset : CameraPresets()) {
    const PresetResolution resolution = Resolutions(preset).front();
    const std::vector<PresetCamera> cameras =
        PresetLensCameras(preset, resolution);
    ASSERT_EQ(cameras.size(), preset.lenses.size()) << preset.name;
    for (size_t lens = 0; lens < cameras.size(); ++lens) {
      const PresetCamera alone =
          PresetLensCamera(preset, resolution, static_cast<int>(lens));
      EXPECT_EQ(cameras[lens].params, alone.params)
          << preset.name << " lens " << lens;
      EXPECT_EQ(cameras[lens].width, alone.width) << preset.name;
    }
  }
}

TEST(CameraPresets, EveryLensModelPassesItsChecks) {
  for (const CameraPreset& preset : CameraPresets()) {
    for (const PresetResolution& resolution : Resolutions(preset)) {
      for (size_t lens = 0; lens < preset.lenses.size(); ++lens) {
        const PresetCamera camera =
            PresetLensCamera(preset, resolution, static_cast<int>(lens));
        const std::string where =
            preset.name + " " + resolution.name + " lens " +
            std::to_string(lens);
        EXPECT_EQ(camera.model_id, ModelIdFromName(preset.model_name)) << where;
        EXPECT_EQ(CheckParams(camera.model_id, camera.params, camera.width,
                              camera.height),
                  "")
            << where;
        // What COLMAP's camera checks ask of it too: a projection that
        // inverts over the whole image.
        EXPECT_EQ(ProjectionOverImageError(camera.model_id, camera.params,
                                           camera.width, camera.height),
                  "")
            << where;
        if (preset.storage == LensStorage::kEquirectangular) continue;
        // The fitted model is the equidistant lens of the circle: its
        // principal point is the circle's centre, and the ray at half the
        // field of view along the image's longer axis lands on the circle
        // (where it is inside the image) to 0.5% of the radius.
        const PresetCircle& circle = resolution.circles[lens];
        EXPECT_NEAR(camera.params[2], circle.cx, 0.002 * circle.r) << where;
        EXPECT_NEAR(camera.params[3], circle.cy, 0.002 * circle.r) << where;
        EXPECT_LT(camera.fit_max_error_px, 0.005 * circle.r) << where;
        const double theta = preset.field_of_view_deg / 2 * kPi / 180 - 1e-6;
        EXPECT_NEAR(RadiusOfRay(camera, circle, theta), circle.r,
                    0.005 * circle.r)
            << where;
      }
    }
  }
}

TEST(CameraPresets, LensesStartFromAnyWholeFieldModel) {
  // Every lens model a preset's lenses may start from, at one resolution
  // of each camera: the same equidistant lens, so the circle's centre and
  // its edge at half the field of view land where the preset's own model
  // puts them.
  for (const std::string model : {"OPENCV_FISHEYE", "THIN_PRISM_FISHEYE",
                                  "EUCM", "UNIFIED_OMNI", "DOUBLE_SPHERE",
                                  "OCAM"}) {
    for (const CameraPreset& preset : CameraPresets()) {
      if (preset.storage == LensStorage::kEquirectangular) continue;
      const PresetResolution resolution = Resolutions(preset).front();
      const PresetCamera camera = PresetLensCamera(preset, resolution, 0, model);
      const std::string where = model + " " + preset.name;
      EXPECT_EQ(camera.model_name, model) << where;
      EXPECT_EQ(camera.model_id, ModelIdFromName(model)) << where;
      EXPECT_EQ(CheckParams(camera.model_id, camera.params, camera.width,
                            camera.height),
                "")
          << where;
      const PresetCircle& circle = resolution.circles[0];
      EXPECT_LT(camera.fit_max_error_px, 0.005 * circle.r) << where;
      const double theta = preset.field_of_view_deg / 2 * kPi / 180 - 1e-6;
      EXPECT_NEAR(RadiusOfRay(camera, circle, 0), 0, 0.005 * circle.r)
          << where;
      EXPECT_NEAR(RadiusOfRay(camera, circle, theta), circle.r,
                  0.005 * circle.r)
          << where;
      // In the rig config, every lens starts from it.
      const nlohmann::json config = nlohmann::json::parse(
          PresetRigConfigJson(preset, resolution, {}, model));
      for (const auto& lens : config[0]["cameras"]) {
        EXPECT_EQ(lens["camera_model_name"], model) << where;
      }
    }
  }
  // A model that is not a lens model, an unknown one, and a lens model for
  // stitched panoramas are refused, naming the option.
  const CameraPreset& theta = FindCameraPreset("ricoh_theta_v");
  for (const std::string model : {"PINHOLE", "OPENCV", "EQUIRECTANGULAR",
                                  "KB4"}) {
    EXPECT_NE(PresetLensModelError(theta, model).find("--camera_model " + model +
                                                      ": not a model for"),
              std::string::npos)
        << model;
  }
  EXPECT_EQ(PresetLensModelError(theta, ""), "");
  RigPresetRequest stitched;
  stitched.camera = "gopro_max";
  stitched.camera_model = "EUCM";
  EXPECT_NE(ErrorOf([&] { ResolveRigPreset(stitched); })
                .find("stores stitched panoramas"),
            std::string::npos);
  stitched.camera_model = "EQUIRECTANGULAR";
  EXPECT_EQ(ResolveRigPreset(stitched).model_name, "EQUIRECTANGULAR");
  RigPresetRequest request;
  request.camera = "ricoh_theta_v";
  EXPECT_EQ(ResolveRigPreset(request).model_name, "DOUBLE_SPHERE");
  request.camera_model = "OPENCV_FISHEYE";
  EXPECT_EQ(ResolveRigPreset(request).model_name, "OPENCV_FISHEYE");
  request.camera_model = "PINHOLE";
  EXPECT_NE(ErrorOf([&] { ResolveRigPreset(request); }), "");
}

TEST(CameraPresets, EquidistantLensCameraFitsTheWholeCircleWhereverItLies) {
  // A 195° lens whose circle the frame crops top and bottom (its centre 300
  // px below the top edge of a 1600 x 1088 image, radius 560): fitted over
  // the whole circle, each model puts the axis on the circle's centre, the
  // rays at 45° and 90° where the equidistant lens has them and the edge of
  // the field on the circle.
  const PresetCircle circle{800.5, 300.25, 560};
  const double theta_max = 97.5 * kPi / 180;
  for (const std::string model : {"OPENCV_FISHEYE", "THIN_PRISM_FISHEYE",
                                  "EUCM", "UNIFIED_OMNI", "DOUBLE_SPHERE",
                                  "OCAM"}) {
    const PresetCamera camera = EquidistantLensCamera(model, circle, 195);
    EXPECT_EQ(camera.model_id, ModelIdFromName(model)) << model;
    EXPECT_EQ(camera.width, 0) << model;
    EXPECT_EQ(CheckParams(camera.model_id, camera.params, 1600, 1088), "")
        << model;
    EXPECT_LT(camera.fit_max_error_px, 0.005 * circle.r) << model;
    // RadiusOfRay's ray lies along x for a camera of width >= height.
    for (const double theta : {0.0, kPi / 4, kPi / 2, theta_max - 1e-6}) {
      EXPECT_NEAR(RadiusOfRay(camera, circle, theta),
                  circle.r * theta / theta_max, 0.005 * circle.r)
          << model << " at " << theta * 180 / kPi << "°";
    }
  }
  // With the image's size, the part inside it is fitted: a preset lens is
  // that fit (the Theta V at 4K: 1920 x 1920 lens images).
  const CameraPreset& theta_v = FindCameraPreset("ricoh_theta_v");
  const PresetResolution resolution = FindPresetResolution(theta_v, "4k");
  const PresetCamera preset_lens = PresetLensCamera(theta_v, resolution, 0);
  const PresetCamera same = EquidistantLensCamera(
      preset_lens.model_name, resolution.circles[0],
      theta_v.field_of_view_deg, preset_lens.width, preset_lens.height);
  EXPECT_EQ(same.params, preset_lens.params);
  EXPECT_EQ(same.width, preset_lens.width);
  // What a specification cannot start: each refusal names the value.
  EXPECT_NE(ErrorOf([&] { EquidistantLensCamera("PINHOLE", circle, 195); })
                .find("PINHOLE: not a model for"),
            std::string::npos);
  for (const double fov : {0.0, -10.0, 360.0, std::nan("")}) {
    EXPECT_NE(ErrorOf([&] { EquidistantLensCamera("EUCM", circle, fov); })
                  .find("field of view"),
              std::string::npos)
        << fov;
  }
  for (const PresetCircle bad : {PresetCircle{800, 300, 0},
                                 PresetCircle{800, 300, -5},
                                 PresetCircle{800, 300, 0.5},
                                 PresetCircle{800, 300, 2e6},
                                 PresetCircle{std::nan(""), 300, 560},
                                 PresetCircle{800, 300, HUGE_VAL}}) {
    EXPECT_NE(ErrorOf([&] { EquidistantLensCamera("EUCM", bad, 195); })
                  .find("image circle"),
              std::string::npos)
        << bad.cx << " " << bad.r;
  }
}

TEST(CameraPresets, CirclesAreConsistentPerResolution) {
  for (const CameraPreset& preset : CameraPresets()) {
    const std::vector<PresetResolution> resolutions = Resolutions(preset);
    ASSERT_FALSE(resolutions.empty()) << preset.name;
    std::set<std::string> names;
    for (const PresetResolution& resolution : resolutions) {
      const std::string where = preset.name + " " + resolution.name;
      EXPECT_TRUE(names.insert(resolution.name).second) << where;
      EXPECT_FALSE(resolution.source.empty()) << where;
      // The name and the size find this resolution.
      EXPECT_EQ(FindPresetResolution(preset, resolution.name).width,
                resolution.width);
      EXPECT_EQ(FindPresetResolution(preset, resolution.width,
                                     resolution.height)
                    .name,
                resolution.name);
      const Eigen::Vector2i size = LensImageSize(preset, resolution);
      if (preset.storage == LensStorage::kEquirectangular) {
        EXPECT_TRUE(resolution.circles.empty()) << where;
        EXPECT_EQ(size.x(), 2 * size.y()) << where;
        continue;
      }
      if (preset.storage == LensStorage::kSideBySide) {
        EXPECT_EQ(resolution.width % 2, 0) << where;
      }
      ASSERT_EQ(resolution.circles.size(), preset.lenses.size()) << where;
      for (const PresetCircle& circle : resolution.circles) {
        // As the splitter wants them: centre inside the lens image, a
        // circle of a lens beyond 180° covering most of it (it may be
        // cropped by the image's edges, not more than to half its
        // diameter).
        EXPECT_GT(circle.cx, 0) << where;
        EXPECT_LT(circle.cx, size.x()) << where;
        EXPECT_GT(circle.cy, 0) << where;
        EXPECT_LT(circle.cy, size.y()) << where;
        EXPECT_GE(2 * circle.r, 0.9 * std::min(size.x(), size.y())) << where;
        EXPECT_LE(2 * circle.r, 2 * std::max(size.x(), size.y())) << where;
        // Relative to the first resolution: the same circle at another
        // scale (within 2% of the image).
        const PresetResolution& first = resolutions.front();
        const Eigen::Vector2i first_size = LensImageSize(preset, first);
        const PresetCircle& reference = first.circles.front();
        EXPECT_NEAR(circle.r / size.y(), reference.r / first_size.y(), 0.02)
            << where;
        EXPECT_NEAR(circle.cx / size.x(), reference.cx / first_size.x(), 0.02)
            << where;
        EXPECT_NEAR(circle.cy / size.y(), reference.cy / first_size.y(), 0.02)
            << where;
      }
    }
  }
}

TEST(CameraPresets, LensPosesAreRigidMotions) {
  for (const CameraPreset& preset : CameraPresets()) {
    ASSERT_FALSE(preset.lenses.empty()) << preset.name;
    const PresetLens& reference = preset.lenses.front();
    for (size_t lens = 0; lens < preset.lenses.size(); ++lens) {
      const std::string where = preset.name + " lens " + std::to_string(lens);
      const PresetLens& camera = preset.lenses[lens];
      EXPECT_NEAR(camera.body_from_cam.norm(), 1, 1e-12) << where;
      const Eigen::Matrix3d R =
          PresetCamFromRigRotation(preset, static_cast<int>(lens))
              .toRotationMatrix();
      EXPECT_TRUE((R * R.transpose()).isIdentity(1e-12)) << where;
      EXPECT_NEAR(R.determinant(), 1, 1e-12) << where;
      const Eigen::Vector3d t =
          PresetCamFromRigTranslation(preset, static_cast<int>(lens));
      // The lens's centre in the rig frame (lens 0's) is -R^T t: its offset
      // from lens 0 in the body, seen from lens 0.
      const Eigen::Vector3d centre_in_rig = -R.transpose() * t;
      const Eigen::Vector3d expected =
          reference.body_from_cam.conjugate() *
          (camera.centre_in_body - reference.centre_in_body);
      EXPECT_TRUE(centre_in_rig.isApprox(expected, 1e-12) ||
                  (centre_in_rig - expected).norm() < 1e-15)
          << where;
      // Offsets are a few centimetres.
      EXPECT_LE(t.norm(), 0.2) << where;
    }
    if (preset.lenses.size() == 2) {
      // Back to back: lens 1 looks the opposite way.
      const Eigen::Vector3d axis_in_rig =
          PresetCamFromRigRotation(preset, 1).conjugate() *
          Eigen::Vector3d::UnitZ();
      EXPECT_NEAR(axis_in_rig.z(), -1, 1e-12) << preset.name;
    }
  }
  // The Vuze ring: stereo partners parallel and 6 cm apart, pairs 90° apart.
  const CameraPreset& vuze = FindCameraPreset("vuze");
  ASSERT_EQ(vuze.lenses.size(), 8u);
  for (int lens = 0; lens < 8; ++lens) {
    const Eigen::Vector3d axis =
        PresetCamFromRigRotation(vuze, lens).conjugate() *
        Eigen::Vector3d::UnitZ();
    const double angle_deg =
        std::acos(std::max(-1.0, std::min(1.0, axis.z()))) * 180 / kPi;
    EXPECT_NEAR(angle_deg, 90.0 * std::min(lens / 2, 4 - lens / 2), 1e-9)
        << lens;
  }
  EXPECT_NEAR(PresetCamFromRigTranslation(vuze, 1).norm(), 0.06, 1e-12);
}

TEST(CameraPresets, RigConfigHasWhatRigConfiguratorReads) {
  for (const CameraPreset& preset : CameraPresets()) {
    const PresetResolution resolution = Resolutions(preset).front();
    const nlohmann::json config =
        nlohmann::json::parse(PresetRigConfigJson(preset, resolution));
    ASSERT_TRUE(config.is_array()) << preset.name;
    ASSERT_EQ(config.size(), 1u) << preset.name;
    const nlohmann::json& cameras = config[0].at("cameras");
    ASSERT_EQ(cameras.size(), preset.lenses.size()) << preset.name;
    std::set<std::string> affixes;
    for (size_t lens = 0; lens < cameras.size(); ++lens) {
      const std::string where = preset.name + " lens " + std::to_string(lens);
      const nlohmann::json& camera = cameras[lens];
      const std::string affix = camera.at("image_prefix").get<std::string>() +
                                "|" + camera.value("image_suffix", "");
      EXPECT_NE(affix, "|") << where;
      EXPECT_TRUE(affixes.insert(affix).second) << where;
      EXPECT_EQ(camera.value("ref_sensor", false), lens == 0) << where;
      EXPECT_EQ(camera.contains("cam_from_rig_rotation"), lens > 0) << where;
      EXPECT_EQ(camera.contains("cam_from_rig_translation"), lens > 0)
          << where;
      if (lens > 0) {
        const std::vector<double> q = camera.at("cam_from_rig_rotation");
        const std::vector<double> t = camera.at("cam_from_rig_translation");
        ASSERT_EQ(q.size(), 4u) << where;
        ASSERT_EQ(t.size(), 3u) << where;
        const Eigen::Quaterniond expected =
            PresetCamFromRigRotation(preset, static_cast<int>(lens));
        EXPECT_NEAR(std::abs(Eigen::Quaterniond(q[0], q[1], q[2], q[3])
                                 .dot(expected)),
                    1, 1e-12)
            << where;
        EXPECT_TRUE(Eigen::Vector3d(t[0], t[1], t[2])
                        .isApprox(PresetCamFromRigTranslation(
                                      preset, static_cast<int>(lens)),
                                  1e-12) ||
                    Eigen::Vector3d(t[0], t[1], t[2]).norm() < 1e-15)
            << where;
      }
      const int model_id =
          ModelIdFromName(camera.at("camera_model_name").get<std::string>());
      const std::vector<double> params = camera.at("camera_params");
      const Eigen::Vector2i size = LensImageSize(preset, resolution);
      EXPECT_EQ(CheckParams(model_id, params, size.x(), size.y()), "")
          << where;
    }
  }
  // The splitter's folders take the place of the preset's.
  const CameraPreset& fusion = FindCameraPreset("gopro_fusion");
  const nlohmann::json config = nlohmann::json::parse(PresetRigConfigJson(
      fusion, fusion.resolutions.front(), {"front", "back"}));
  EXPECT_EQ(config[0]["cameras"][1]["image_prefix"], "back/");
  EXPECT_NE(ErrorOf([&] {
              PresetRigConfigJson(fusion, fusion.resolutions.front(), {"a"});
            }),
            "");
}

TEST(CameraPresets, RequestsAreCheckedOnce) {
  RigPresetRequest request;
  request.camera = "GoPro_Fusion";
  EXPECT_EQ(ResolveRigPreset(request).resolution.name, "3k");
  request.resolution = "PHOTO";
  EXPECT_EQ(ResolveRigPreset(request).resolution.width, 3104);
  request.resolution = "2704x2624";
  EXPECT_EQ(ResolveRigPreset(request).resolution.name, "5.2k");
  request.resolution.clear();
  request.image_width = 3104;
  request.image_height = 3000;
  EXPECT_EQ(ResolveRigPreset(request).resolution.name, "photo");

  // A size or name the preset lacks: named, with the known ones.
  request.image_width = 3000;
  std::string error = ErrorOf([&] { ResolveRigPreset(request); });
  EXPECT_NE(error.find("3000x3000"), std::string::npos) << error;
  EXPECT_NE(error.find("photo (3104x3000)"), std::string::npos) << error;
  request.image_width = 0;
  request.image_height = 0;
  request.resolution = "8k";
  error = ErrorOf([&] { ResolveRigPreset(request); });
  EXPECT_NE(error.find("\"8k\""), std::string::npos) << error;
  EXPECT_NE(error.find("5.2k (2704x2624)"), std::string::npos) << error;
  for (const char* bad : {"x", "0x0", "12x", "x12", "-5x3", "1234567x2",
                          "12x3x4", " 12x6"}) {
    request.resolution = bad;
    EXPECT_NE(ErrorOf([&] { ResolveRigPreset(request); }), "") << bad;
  }
  // Both ways of giving a size, or half of one: refused.
  request.resolution = "3k";
  request.image_width = 1568;
  request.image_height = 1504;
  EXPECT_NE(ErrorOf([&] { ResolveRigPreset(request); }), "");
  request.resolution.clear();
  request.image_height = 0;
  EXPECT_NE(ErrorOf([&] { ResolveRigPreset(request); }), "");

  // The generic dual fisheye needs a 2:1 size.
  RigPresetRequest generic;
  generic.camera = "dual_fisheye";
  EXPECT_NE(ErrorOf([&] { ResolveRigPreset(generic); }).find("size"),
            std::string::npos);
  generic.resolution = "4000x2000";
  const ResolvedPreset resolved = ResolveRigPreset(generic);
  EXPECT_EQ(resolved.resolution.circles[1].r, 1000);
  generic.resolution = "4000x2001";
  EXPECT_NE(ErrorOf([&] { ResolveRigPreset(generic); }), "");

  RigPresetRequest unknown;
  unknown.camera = "list";
  EXPECT_NE(ErrorOf([&] { ResolveRigPreset(unknown); }).find("gopro_fusion"),
            std::string::npos);
}

}  // namespace
}  // namespace sphera
