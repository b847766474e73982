#include "calibration/camera_presets.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <nlohmann/json.hpp>

#include "calibration/model_conversion.h"
#include "camera_models/registry.h"

namespace sphera {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Quaterniond AboutAxis(double degrees, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * kPi / 180, axis));
}

// Two lenses back to back, SEPARATION metres apart along the optical axis of
// lens 0 (which looks along +z of the body), lens 1 turned 180° about the
// body's TURN_AXIS: y (the image's vertical) when both circles are upright
// in the stored images, x when the camera stores them turned 90° (both the
// same way).
std::vector<PresetLens> BackToBack(double separation,
                                   const Eigen::Vector3d& turn_axis) {
  PresetLens front;
  front.folder = "lens0";
  front.centre_in_body = Eigen::Vector3d(0, 0, separation / 2);
  PresetLens back;
  back.folder = "lens1";
  back.body_from_cam = AboutAxis(180, turn_axis);
  back.centre_in_body = Eigen::Vector3d(0, 0, -separation / 2);
  return {front, back};
}

// Both circles of a side-by-side frame WIDTH x HEIGHT centred in their
// halves, radius RADIUS_FRACTION of the half's height / 2.
PresetResolution SideBySide(const std::string& name, int width, int height,
                            double radius_fraction, const std::string& source) {
  const PresetCircle circle{width / 4.0, height / 2.0,
                            radius_fraction * height / 2.0};
  return {name, width, height, {circle, circle}, source};
}

// An 8-lens ring of four stereo pairs looking out of the four sides of a
// square body (pair k along the body direction turned 90° k about y, to the
// right seen from above), each pair's lenses BASELINE apart side by side
// and DEPTH in front of the body's centre; lens i's file is NAME_<i+1>.JPG,
// left lens of a pair first.
std::vector<PresetLens> StereoRing(double baseline, double depth) {
  std::vector<PresetLens> lenses;
  for (int pair = 0; pair < 4; ++pair) {
    const Eigen::Quaterniond body_from_cam =
        AboutAxis(90.0 * pair, Eigen::Vector3d::UnitY());
    for (int side = 0; side < 2; ++side) {
      PresetLens lens;
      lens.file_suffix = "_" + std::to_string(lenses.size() + 1) + ".JPG";
      lens.body_from_cam = body_from_cam;
      lens.centre_in_body =
          body_from_cam * Eigen::Vector3d((side == 0 ? -0.5 : 0.5) * baseline,
                                          0, depth);
      lenses.push_back(lens);
    }
  }
  return lenses;
}

const Eigen::Vector3d kUpright = Eigen::Vector3d::UnitY();
const Eigen::Vector3d kTurned90 = Eigen::Vector3d::UnitX();

// Nominal rules, named once.
const char* const kInscribed =
    "nominal: circles inscribed in the frame's halves";
const char* const kInstaCircles =
    "nominal: centred in the halves, r = 0.4926 H / 2 as in the maker's "
    "offset strings of its ONE-series cameras (Insta360 UniversalBlender "
    "sample, 3040x1520: r 748.8 and 742.2)";

// Two lenses back to back whose circles a file holds side by side, the
// starting model DOUBLE_SPHERE.
CameraPreset SideBySideDualFisheye(const std::string& name,
                                   const std::string& description,
                                   double separation,
                                   const Eigen::Vector3d& turn_axis,
                                   double field_of_view_deg,
                                   std::vector<PresetResolution> resolutions,
                                   const std::string& source) {
  return {name,
          description,
          LensStorage::kSideBySide,
          BackToBack(separation, turn_axis),
          std::move(resolutions),
          false,
          "DOUBLE_SPHERE",
          field_of_view_deg,
          source};
}

PresetResolution Inscribed(const std::string& name, int width, int height) {
  return SideBySide(name, width, height, 1.0, kInscribed);
}

PresetResolution InstaResolution(const std::string& name, int width,
                                 int height) {
  return SideBySide(name, width, height, 0.9852, kInstaCircles);
}

std::vector<CameraPreset> MakePresets() {
  std::vector<CameraPreset> presets;

  // Ricoh Theta S: dual-fisheye video and live stream (its stills are
  // stitched in the camera). Lens 0 (left circle) is the back lens. The
  // 1920x1080 circles, the equidistant projection and the 202° field were
  // measured on a Theta SC (the same optics) by Leo Sutic
  // (monochrome.sutic.nu, 2017-08-03, "Ricoh Theta SC lens parameters"),
  // as was the alignment of the lenses (yaw 178.8°, pitch 1.1°, roll 0.7°:
  // 180° about the vertical nominally). Offset nominal: the body is
  // 22.9 mm thick with its lenses (Ricoh's specification).
  presets.push_back(SideBySideDualFisheye(
      "ricoh_theta_s",
      "Ricoh Theta S / SC: two 202° lenses side by side in the dual-fisheye "
      "video and live stream",
      0.02, kUpright, 202,
      {{"video", 1920, 1080, {{480, 480, 480}, {480, 480, 480}},
        "measured on a Theta SC (Sutic 2017)"},
       {"live", 1280, 720, {{320, 320, 320}, {320, 320, 320}},
        "nominal: the video's circles scaled by 2/3"}},
      "field of view and lens alignment measured on a Theta SC (Sutic "
      "2017); offset nominal (body 22.9 mm)"));
  // Theta V, Z1, X: the same folded twin-lens design (Ricoh); dual-fisheye
  // video and streaming sizes from Ricoh's API documentation, circles,
  // field of view and offsets nominal (bodies 22.9, 29.7 and 29 mm thick).
  const std::string theta_nominal =
      "nominal: field of view as the Theta S, offset from the body's ";
  presets.push_back(SideBySideDualFisheye(
      "ricoh_theta_v",
      "Ricoh Theta V: two lenses side by side in the dual-fisheye 4K video",
      0.02, kUpright, 202,
      {Inscribed("4k", 3840, 1920), Inscribed("2k", 1920, 960)},
      theta_nominal + "22.9 mm"));
  presets.push_back(SideBySideDualFisheye(
      "ricoh_theta_z1",
      "Ricoh Theta Z1: two lenses side by side in the dual-fisheye video "
      "and DNG stills",
      0.025, kUpright, 202,
      {Inscribed("raw", 7296, 3648), Inscribed("4k", 3840, 1920)},
      theta_nominal + "29.7 mm"));
  presets.push_back(SideBySideDualFisheye(
      "ricoh_theta_x",
      "Ricoh Theta X: two lenses side by side in the dual-fisheye video",
      0.025, kUpright, 202,
      {Inscribed("5.7k", 5760, 2880), Inscribed("4k", 3840, 1920)},
      theta_nominal + "29 mm"));

  // Insta360 ONE X2, X3, X4: .insp stills (JPEG) and single-file videos hold
  // both circles side by side, each turned 90° (the maker's offset strings
  // give both lenses a roll of 90°), so the lenses are 180° apart about the
  // images' x axis. Sizes from Insta360's specifications; circles nominal
  // (kInstaCircles); 200° field and offsets (body thickness 29.8, 33.1,
  // 37.6 mm) nominal.
  const std::string insta_nominal =
      "nominal: lens roll from the maker's offset strings, offset from the "
      "body's ";
  presets.push_back(SideBySideDualFisheye(
      "insta360_one_x2",
      "Insta360 ONE X2: two 200° lenses side by side in .insp stills and "
      "4K videos",
      0.03, kTurned90, 200,
      {InstaResolution("photo", 6080, 3040),
       InstaResolution("4k", 3840, 1920)},
      insta_nominal + "29.8 mm"));
  presets.push_back(SideBySideDualFisheye(
      "insta360_x3",
      "Insta360 X3: two 200° lenses side by side in .insp stills and videos",
      0.033, kTurned90, 200,
      {InstaResolution("72mp", 11968, 5984),
       InstaResolution("18mp", 5952, 2976),
       InstaResolution("5.7k", 5760, 2880)},
      insta_nominal + "33.1 mm"));
  presets.push_back(SideBySideDualFisheye(
      "insta360_x4",
      "Insta360 X4: two 200° lenses side by side in .insp stills and videos",
      0.038, kTurned90, 200,
      {InstaResolution("72mp", 11904, 5952),
       InstaResolution("18mp", 5952, 2976),
       InstaResolution("8k", 7680, 3840)},
      insta_nominal + "37.6 mm"));

  // GoPro Fusion: one file per lens in two folders (FR/GPFR0003.JPG,
  // BK/GPBK0003.JPG; photos GF/GB). Circles and the 190° field from the
  // maker's parameter files (GoPro Fusion parameter examples of
  // trek-view/fusion2sphere: video-3k-mode.txt, video-5_2k-mode.txt,
  // photo-mode.txt); upright circles, offset nominal (body 40 mm thick).
  CameraPreset fusion = SideBySideDualFisheye(
      "gopro_fusion",
      "GoPro Fusion: two 190° lenses, one folder per lens (FR/, BK/)", 0.04,
      kUpright, 190,
      {{"3k", 1568, 1504, {{779, 742, 765}, {779, 742, 765}},
        "maker's parameter file (3K video)"},
       {"5.2k", 2704, 2624, {{1345, 1303, 1335}, {1337, 1303, 1338}},
        "maker's parameter file (5.2K video)"},
       {"photo", 3104, 3000, {{1543, 1484, 1520}, {1536, 1500, 1534}},
        "maker's parameter file (18-MP photo)"}},
      "field of view from the maker's parameter files; lens directions and "
      "offset nominal (body 40 mm)");
  fusion.storage = LensStorage::kFolderPerLens;
  presets.push_back(fusion);

  // GoPro Max: no lens images. Its .360 videos hold the stitched sphere as
  // two equi-angular cubemap tracks and its photos are equirectangular
  // (GoPro's specification), so the preset is one EQUIRECTANGULAR camera.
  PresetLens pano;
  pano.folder = "pano";
  presets.push_back(
      {"gopro_max",
       "GoPro Max: stitched in the camera (equirectangular photos, .360 "
       "video exported equirectangular); one EQUIRECTANGULAR camera",
       LensStorage::kEquirectangular,
       {pano},
       {{"photo", 5760, 2880, {}, "GoPro's specification (16.6 MP)"},
        {"5.6k", 5376, 2688, {}, "GoPro's specification (5.6K export)"}},
       false,
       "EQUIRECTANGULAR",
       360,
       "GoPro's specification"});

  // Kandao QooCam 8K and QooCam 3, Vuze XR in 360 mode (its two lenses
  // turned back to back): both circles side by side in the raw video
  // (stitched by the makers' desktop programs). Sizes from the makers'
  // specifications; circles, 200° field and offsets nominal.
  presets.push_back(SideBySideDualFisheye(
      "kandao_qoocam_8k",
      "Kandao QooCam 8K: two 200° lenses side by side in the raw video", 0.03,
      kUpright, 200,
      {Inscribed("8k", 7680, 3840), Inscribed("4k", 3840, 1920)}, "nominal"));
  presets.push_back(SideBySideDualFisheye(
      "kandao_qoocam_3",
      "Kandao QooCam 3: two 200° lenses side by side in the raw video", 0.03,
      kUpright, 200,
      {Inscribed("5.7k", 5760, 2880), Inscribed("4k", 3840, 1920)},
      "nominal"));

  // Humaneyes Vuze: 8 lenses, four stereo pairs on the sides of a square
  // body; each sensor turned 90°, so that its 1920 pixels span 180° top to
  // bottom (onsen.ca, "Vuze camera RAW resolution", 2017). One file per
  // lens, NAME_1.JPG ... NAME_8.JPG. Circle (cropped by the 1080-pixel
  // width), 180° field, 6 cm baselines and 6 cm from the centre nominal.
  presets.push_back(
      {"vuze",
       "Humaneyes Vuze: 8 lenses in 4 stereo pairs, one file per lens "
       "(NAME_1.JPG ... NAME_8.JPG)",
       LensStorage::kFilePerLens,
       StereoRing(0.06, 0.06),
       {{"lens", 1080, 1920, std::vector<PresetCircle>(8, {540, 960, 960}),
         "nominal: 1920 px span 180° (onsen.ca 2017)"}},
       false,
       "EUCM",
       180,
       "nominal: stereo baseline and body size from the specification"});
  presets.push_back(SideBySideDualFisheye(
      "vuze_xr",
      "Humaneyes Vuze XR in 360 mode: two lenses side by side in one frame",
      0.03, kUpright, 200,
      {Inscribed("5.7k", 5760, 2880), Inscribed("4k", 3840, 1920)},
      "nominal"));

  // Any camera of two circles side by side in square halves: inscribed
  // circles, 190° lenses back to back, 3 cm apart (the middle of the 2 to 4
  // cm of the cameras above; the mapper refines its direction). Lenses at
  // one centre would make the rig a panorama, without the baseline its
  // lens offset gives inside each frame.
  CameraPreset generic = SideBySideDualFisheye(
      "dual_fisheye",
      "any dual-fisheye camera: two 190° circles inscribed in the halves of "
      "a 2:1 frame (give its size)",
      0.03, kUpright, 190, {}, "nominal: offset 3 cm");
  generic.any_two_to_one_size = true;
  presets.push_back(generic);
  return presets;
}

std::string Lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  });
  return text;
}

std::string SizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

std::string KnownResolutions(const CameraPreset& preset) {
  if (preset.any_two_to_one_size) {
    return "any WxH with W = 2 H";
  }
  std::string known;
  for (const PresetResolution& resolution : preset.resolutions) {
    known += (known.empty() ? "" : ", ") + resolution.name + " (" +
             SizeText(resolution.width, resolution.height) + ")";
  }
  return known;
}

// "WxH" of positive whole numbers (at most 6 digits each), or false.
bool ParseSize(const std::string& text, int* width, int* height) {
  const size_t x = Lower(text).find('x');
  if (x == std::string::npos || x == 0 || x + 1 == text.size()) return false;
  const std::string parts[2] = {text.substr(0, x), text.substr(x + 1)};
  int values[2];
  for (int i = 0; i < 2; ++i) {
    if (parts[i].size() > 6 ||
        !std::all_of(parts[i].begin(), parts[i].end(), [](char c) {
          return std::isdigit(static_cast<unsigned char>(c));
        })) {
      return false;
    }
    values[i] = std::stoi(parts[i]);
  }
  *width = values[0];
  *height = values[1];
  return *width > 0 && *height > 0;
}

// Shortest text of a rotation or translation component, with the rounding
// noise of 180° turns (6e-17) removed.
double Clean(double value) {
  const double rounded = std::round(value);
  return std::abs(value - rounded) < 1e-12 ? rounded + 0.0 : value;
}

}  // namespace

const char* LensStorageName(LensStorage storage) {
  switch (storage) {
    case LensStorage::kSideBySide:
      return "side by side in one file";
    case LensStorage::kFolderPerLens:
      return "one folder per lens";
    case LensStorage::kFilePerLens:
      return "one file per lens";
    case LensStorage::kEquirectangular:
      return "stitched equirectangular";
  }
  return "";
}

const std::vector<CameraPreset>& CameraPresets() {
  static const std::vector<CameraPreset> presets = MakePresets();
  return presets;
}

const CameraPreset& FindCameraPreset(const std::string& name) {
  std::string known;
  for (const CameraPreset& preset : CameraPresets()) {
    if (preset.name == Lower(name)) return preset;
    known += (known.empty() ? "" : ", ") + preset.name;
  }
  throw std::invalid_argument("--camera: no camera preset \"" + name +
                              "\"; known: " + known + " (or list)");
}

Eigen::Vector2i LensImageSize(const CameraPreset& preset,
                              const PresetResolution& resolution) {
  const int lenses_in_file =
      preset.storage == LensStorage::kSideBySide ? 2 : 1;
  return {resolution.width / lenses_in_file, resolution.height};
}

PresetResolution FindPresetResolution(const CameraPreset& preset, int width,
                                      int height) {
  if (preset.any_two_to_one_size && width > 1 && height > 0 &&
      width == 2 * height) {
    const PresetCircle circle{height / 2.0, height / 2.0, height / 2.0};
    return {SizeText(width, height), width, height, {circle, circle},
            kInscribed};
  }
  for (const PresetResolution& resolution : preset.resolutions) {
    if (resolution.width == width && resolution.height == height) {
      return resolution;
    }
  }
  throw std::invalid_argument(preset.name + " stores no " +
                              SizeText(width, height) + " files; known: " +
                              KnownResolutions(preset));
}

PresetResolution FindPresetResolution(const CameraPreset& preset,
                                      const std::string& name) {
  for (const PresetResolution& resolution : preset.resolutions) {
    if (resolution.name == Lower(name)) return resolution;
  }
  int width = 0;
  int height = 0;
  if (ParseSize(name, &width, &height)) {
    return FindPresetResolution(preset, width, height);
  }
  throw std::invalid_argument("--resolution: " + preset.name +
                              " has no resolution \"" + name +
                              "\"; known: " + KnownResolutions(preset));
}

std::string LensModelError(const std::string& model_name) {
  // The lens models: the sphere models but the panorama's.
  std::string known;
  for (const ModelInfo& info : SphereModels()) {
    if (info.name == std::string("EQUIRECTANGULAR")) continue;
    if (model_name == info.name) return "";
    known += (known.empty() ? "" : ", ") + std::string(info.name);
  }
  return model_name + ": not a model for the lenses of a 360° camera; one of " +
         known;
}

std::string PresetLensModelError(const CameraPreset& preset,
                                 const std::string& model_name) {
  if (model_name.empty() || model_name == preset.model_name) return "";
  if (preset.storage == LensStorage::kEquirectangular) {
    return "--camera_model " + model_name + ": " + preset.name +
           " stores stitched panoramas, one " + preset.model_name +
           " camera";
  }
  const std::string error = LensModelError(model_name);
  return error.empty() ? "" : "--camera_model " + error;
}

PresetCamera EquidistantLensCamera(const std::string& model_name,
                                   const PresetCircle& circle,
                                   double field_of_view_deg, int width,
                                   int height) {
  if (const std::string error = LensModelError(model_name); !error.empty()) {
    throw std::invalid_argument(error);
  }
  if (!(field_of_view_deg > 0 && field_of_view_deg < 360)) {
    throw std::invalid_argument(
        "field of view " + std::to_string(field_of_view_deg) +
        " degrees: must be above 0 and below 360");
  }
  // Images up to a million pixels wide.
  constexpr double kMaxPixels = 1e6;
  if (!(std::abs(circle.cx) <= kMaxPixels && std::abs(circle.cy) <= kMaxPixels &&
        circle.r >= 1 && circle.r <= kMaxPixels)) {
    throw std::invalid_argument(
        "image circle (" + std::to_string(circle.cx) + ", " +
        std::to_string(circle.cy) + ", " + std::to_string(circle.r) +
        "): needs a centre within 1e6 pixels and a radius of 1 to 1e6 pixels");
  }
  // Without an image size the circle is fitted whole: in an image that just
  // holds it, the principal point moved back to the circle's centre after.
  const bool whole = width <= 0 || height <= 0;
  const int side = static_cast<int>(std::ceil(2 * circle.r)) + 2;
  const Eigen::Vector2d centre =
      whole ? Eigen::Vector2d(side / 2.0, side / 2.0)
            : Eigen::Vector2d(circle.cx, circle.cy);
  const double theta_max = field_of_view_deg / 2 * kPi / 180;
  const double focal = circle.r / theta_max;
  const ImageFromRayFunction equidistant = [&](const Eigen::Vector3d& ray,
                                               Eigen::Vector2d* pixel) {
    const double theta = std::atan2(ray.head<2>().norm(), ray.z());
    if (theta > theta_max) return false;
    const double radius_xy = ray.head<2>().norm();
    const Eigen::Vector2d direction =
        radius_xy > 0 ? Eigen::Vector2d(ray.head<2>() / radius_xy)
                      : Eigen::Vector2d::Zero();
    *pixel = centre + focal * theta * direction;
    return true;
  };
  // The lens is exact and symmetric about its axis: a few meridians (the
  // image's edges crop some) and samples every 3° describe it.
  LensSamplingOptions sampling;
  sampling.num_meridians = 16;
  sampling.sample_spacing_deg = 3;
  const int fit_width = whole ? side : width;
  const int fit_height = whole ? side : height;
  PresetCamera camera;
  camera.model_name = model_name;
  camera.model_id = ModelIdFromName(model_name);
  camera.width = whole ? 0 : width;
  camera.height = whole ? 0 : height;
  const std::vector<RayPixelSample> samples =
      SampleLensByProjection(equidistant, fit_width, fit_height, sampling);
  const ModelConversion fit =
      FitModelToSamples(camera.model_id, samples, fit_width, fit_height);
  camera.params = fit.params;
  camera.fit_max_error_px = fit.errors.max_error_px;
  if (whole) {
    internal::VisitModel(camera.model_id, [&](auto model) {
      using Model = decltype(model);
      static_assert(Model::kPrincipalPointIdxs.size() == 2 ||
                    Model::kPrincipalPointIdxs.empty());
      if constexpr (Model::kPrincipalPointIdxs.size() == 2) {
        camera.params[Model::kPrincipalPointIdxs[0]] += circle.cx - centre.x();
        camera.params[Model::kPrincipalPointIdxs[1]] += circle.cy - centre.y();
      }
    });
  }
  return camera;
}

PresetCamera PresetLensCamera(const CameraPreset& preset,
                              const PresetResolution& resolution, int lens,
                              const std::string& model_name) {
  if (const std::string error = PresetLensModelError(preset, model_name);
      !error.empty()) {
    throw std::invalid_argument(error);
  }
  const Eigen::Vector2i size = LensImageSize(preset, resolution);
  const std::string name = model_name.empty() ? preset.model_name : model_name;
  if (preset.storage == LensStorage::kEquirectangular) {
    PresetCamera camera;
    camera.width = size.x();
    camera.height = size.y();
    camera.model_name = name;
    camera.model_id = ModelIdFromName(name);
    camera.params = {static_cast<double>(size.x()),
                     static_cast<double>(size.y())};
    return camera;
  }
  // The equidistant lens of the circle: radius r at theta_max.
  return EquidistantLensCamera(name, resolution.circles.at(lens),
                               preset.field_of_view_deg, size.x(), size.y());
}

std::vector<PresetCamera> PresetLensCameras(const CameraPreset& preset,
                                            const PresetResolution& resolution,
                                            const std::string& model_name) {
  std::vector<PresetCamera> cameras;
  for (size_t lens = 0; lens < preset.lenses.size(); ++lens) {
    // A lens of an earlier lens's image circle is that lens's fit.
    size_t same = 0;
    while (same < lens && lens < resolution.circles.size() &&
           !(resolution.circles[same].cx == resolution.circles[lens].cx &&
             resolution.circles[same].cy == resolution.circles[lens].cy &&
             resolution.circles[same].r == resolution.circles[lens].r)) {
      ++same;
    }
    cameras.push_back(same < lens ? cameras[same]
                                  : PresetLensCamera(preset, resolution,
                                                     static_cast<int>(lens),
                                                     model_name));
  }
  return cameras;
}

Eigen::Quaterniond PresetCamFromRigRotation(const CameraPreset& preset,
                                            int lens) {
  Eigen::Quaterniond q = (preset.lenses.at(lens).body_from_cam.conjugate() *
                          preset.lenses.at(0).body_from_cam)
                             .normalized();
  // q and -q are one rotation: the one whose first non-zero component of
  // (w, x, y, z) is positive, so that a turn of 180° about y reads
  // (0, 0, 1, 0) as the splitter writes it.
  for (const double component : {q.w(), q.x(), q.y(), q.z()}) {
    if (std::abs(component) > 1e-12) {
      if (component < 0) q.coeffs() *= -1;
      break;
    }
  }
  return q;
}

Eigen::Vector3d PresetCamFromRigTranslation(const CameraPreset& preset,
                                            int lens) {
  const PresetLens& camera = preset.lenses.at(lens);
  return camera.body_from_cam.conjugate() *
         (preset.lenses.at(0).centre_in_body - camera.centre_in_body);
}

std::string PresetRigConfigJson(const CameraPreset& preset,
                                const PresetResolution& resolution,
                                const std::vector<std::string>& lens_folders,
                                const std::string& model_name) {
  if (!lens_folders.empty() && lens_folders.size() != preset.lenses.size()) {
    throw std::invalid_argument(
        preset.name + " has " + std::to_string(preset.lenses.size()) +
        " lenses, but " + std::to_string(lens_folders.size()) +
        " folders were given");
  }
  const std::vector<PresetCamera> lens_cameras =
      PresetLensCameras(preset, resolution, model_name);
  nlohmann::ordered_json cameras = nlohmann::ordered_json::array();
  for (size_t lens = 0; lens < preset.lenses.size(); ++lens) {
    nlohmann::ordered_json camera;
    if (preset.storage == LensStorage::kFilePerLens) {
      camera["image_prefix"] = "";
      camera["image_suffix"] = preset.lenses[lens].file_suffix;
    } else {
      camera["image_prefix"] =
          (lens_folders.empty() ? preset.lenses[lens].folder
                                : lens_folders[lens]) +
          "/";
    }
    if (lens == 0) {
      camera["ref_sensor"] = true;
    } else {
      const Eigen::Quaterniond q =
          PresetCamFromRigRotation(preset, static_cast<int>(lens));
      const Eigen::Vector3d t =
          PresetCamFromRigTranslation(preset, static_cast<int>(lens));
      camera["cam_from_rig_rotation"] = {Clean(q.w()), Clean(q.x()),
                                         Clean(q.y()), Clean(q.z())};
      camera["cam_from_rig_translation"] = {Clean(t.x()), Clean(t.y()),
                                            Clean(t.z())};
    }
    const PresetCamera& lens_camera = lens_cameras[lens];
    camera["camera_model_name"] = lens_camera.model_name;
    camera["camera_params"] = lens_camera.params;
    cameras.push_back(camera);
  }
  nlohmann::ordered_json rig;
  rig["cameras"] = cameras;
  return nlohmann::ordered_json::array({rig}).dump(2) + "\n";
}

ResolvedPreset ResolveRigPreset(const RigPresetRequest& request) {
  ResolvedPreset resolved;
  resolved.preset = &FindCameraPreset(request.camera);
  const CameraPreset& preset = *resolved.preset;
  const bool has_size = request.image_width != 0 || request.image_height != 0;
  if (has_size && (request.image_width <= 0 || request.image_height <= 0 ||
                   request.image_width > 999999 ||
                   request.image_height > 999999)) {
    throw std::invalid_argument(
        "--image_width and --image_height go together and are in [1, "
        "999999], got " +
        std::to_string(request.image_width) + " and " +
        std::to_string(request.image_height));
  }
  if (has_size && !request.resolution.empty()) {
    throw std::invalid_argument(
        "give --resolution or --image_width and --image_height, not both");
  }
  if (const std::string error =
          PresetLensModelError(preset, request.camera_model);
      !error.empty()) {
    throw std::invalid_argument(error);
  }
  resolved.model_name =
      request.camera_model.empty() ? preset.model_name : request.camera_model;
  if (!request.resolution.empty()) {
    resolved.resolution = FindPresetResolution(preset, request.resolution);
  } else if (has_size) {
    resolved.resolution = FindPresetResolution(preset, request.image_width,
                                               request.image_height);
  } else if (!preset.resolutions.empty()) {
    resolved.resolution = preset.resolutions.front();
  } else {
    throw std::invalid_argument(
        preset.name + " needs the size of its files: --resolution WxH or "
                      "--image_width and --image_height (" +
        KnownResolutions(preset) + ")");
  }
  return resolved;
}

std::string PresetListText() {
  std::ostringstream text;
  for (const CameraPreset& preset : CameraPresets()) {
    text << preset.name << ": " << preset.description << "; "
         << KnownResolutions(preset) << "\n";
  }
  return text.str();
}

}  // namespace sphera
