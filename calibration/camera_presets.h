// Presets of common 360° cameras: how a camera stores its lenses, the image
// circles per resolution, the lenses' poses in the rig and a starting lens
// model, for `colmap rig_preset` and `dual_fisheye_splitter --camera`.
//
// Values come from public specifications and the makers' own parameter
// files; camera_presets.cc names the source of each and says "nominal" where
// a value was not measured (then it is a start that the mapper refines: the
// lens offsets, the intrinsics and, for most cameras, the lenses' exact
// directions).
//
// Mathematics
// -----------
// Lens model. Every preset lens is taken as equidistant (image radius
// f * theta from the circle's centre) with its image circle at half its field
// of view theta_max, so f = r / theta_max. The preset's model (one of
// camera_models/registry.h, e.g. DOUBLE_SPHERE) is fitted to that projection
// over the part of the circle inside the lens image
// (calibration/model_conversion.h); a resolution's model is therefore its
// own circle's, not a scaled copy of another resolution's.
//
// Rig. A lens's pose is given in the camera body's frame (x right, y down,
// z forward, as COLMAP's cameras; metres): body_from_cam (rotation) and its
// centre. The rig frame is lens 0's camera frame (lens 0 is the reference
// sensor), so for lens i
//   cam_i_from_rig = cam_i_from_body * body_from_cam_0,
//   R = R_i^T R_0,  t = R_i^T (c_0 - c_i).
//
// No COLMAP headers: Eigen, nlohmann-json and calibration/ only.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sphera {

// How a camera stores the images of its lenses.
enum class LensStorage {
  // All circles side by side in one file, lens 0 on the left (Ricoh Theta,
  // Insta360): split by `colmap dual_fisheye_splitter --input_path`.
  kSideBySide,
  // One folder per lens, files named with a lens tag (GoPro Fusion:
  // FR/GPFR0003.JPG, BK/GPBK0003.JPG): `dual_fisheye_splitter --front_path
  // --back_path` pairs and renames them.
  kFolderPerLens,
  // One file per lens in one folder, NAME<file_suffix> (NAME_1.JPG ...
  // NAME_8.JPG): the rig config groups them by suffix, no splitting.
  kFilePerLens,
  // No lens images at all: the camera stitches in the camera (equirectangular
  // files); the preset is a rig of one EQUIRECTANGULAR camera.
  kEquirectangular,
};

const char* LensStorageName(LensStorage storage);

// An image circle in lens image pixels (COLMAP's convention: the image's
// corner at 0, 0); it may reach past the image's edges.
struct PresetCircle {
  double cx = 0;
  double cy = 0;
  double r = 0;
};

// One stored resolution: the size of a stored file (side by side: the whole
// frame of all lenses) and each lens's circle.
struct PresetResolution {
  std::string name;  // "3k", "photo", ...
  int width = 0;
  int height = 0;
  std::vector<PresetCircle> circles;  // one per lens
  // Where the circles come from, or "nominal: <rule>".
  std::string source;
};

struct PresetLens {
  // The lens's folder in the split output (side by side, folder per lens:
  // the splitter's lens names) or its file name ending (file per lens).
  std::string folder;
  std::string file_suffix;  // kFilePerLens only
  // body_from_cam and the lens centre in the body frame (metres).
  Eigen::Quaterniond body_from_cam = Eigen::Quaterniond::Identity();
  Eigen::Vector3d centre_in_body = Eigen::Vector3d::Zero();
};

struct CameraPreset {
  std::string name;         // "gopro_fusion"
  std::string description;  // one line
  LensStorage storage = LensStorage::kSideBySide;
  std::vector<PresetLens> lenses;
  std::vector<PresetResolution> resolutions;
  // Any frame of two square halves (W = 2 H) is accepted, its circles
  // inscribed in the halves (the generic dual_fisheye).
  bool any_two_to_one_size = false;
  std::string model_name;  // the starting model, one of registry.h's
  double field_of_view_deg = 0;
  // Where the lens poses, offsets and field of view come from.
  std::string source;
};

// Every preset, in the order `rig_preset --camera list` prints them.
const std::vector<CameraPreset>& CameraPresets();

// The preset called NAME (any letter case); throws std::invalid_argument
// naming NAME and listing the known ones.
const CameraPreset& FindCameraPreset(const std::string& name);

// The width and height of one lens image of a stored file of the resolution.
Eigen::Vector2i LensImageSize(const CameraPreset& preset,
                              const PresetResolution& resolution);

// The preset's resolution of a stored file WIDTH x HEIGHT; throws
// std::invalid_argument naming the size and listing the known ones.
PresetResolution FindPresetResolution(const CameraPreset& preset, int width,
                                      int height);

// The preset's resolution named NAME (any letter case) or written "WxH";
// throws std::invalid_argument naming it and listing the known ones.
PresetResolution FindPresetResolution(const CameraPreset& preset,
                                      const std::string& name);

// The starting camera of one lens at a resolution: the preset's model fitted
// to its equidistant lens (see above).
struct PresetCamera {
  int model_id = -1;
  std::string model_name;
  std::vector<double> params;
  int width = 0;  // the lens image
  int height = 0;
  double fit_max_error_px = 0;  // of the fit, over the circle
};
// Why MODEL_NAME is not a model for a fisheye lens (registry.h's
// SphereModels but EQUIRECTANGULAR), or "".
std::string LensModelError(const std::string& model_name);

// The starting camera of a lens known from its specification: MODEL_NAME
// fitted to the equidistant lens (radius f * theta from the circle's centre,
// f = r / theta_max) whose field of view FIELD_OF_VIEW_DEG fills CIRCLE, over
// the part of the circle inside a WIDTH x HEIGHT lens image; with WIDTH or
// HEIGHT 0 over the whole circle, wherever it lies (the result's width and
// height are then 0). Throws std::invalid_argument naming the value: a model
// LensModelError refuses, a field of view outside (0, 360) degrees, a circle
// whose centre is not within 1e6 pixels or whose radius is not 1 to 1e6
// pixels.
PresetCamera EquidistantLensCamera(const std::string& model_name,
                                   const PresetCircle& circle,
                                   double field_of_view_deg, int width = 0,
                                   int height = 0);

// MODEL_NAME (empty: the preset's model_name) must be a whole-field lens
// model (PresetLensModelError).
PresetCamera PresetLensCamera(const CameraPreset& preset,
                              const PresetResolution& resolution, int lens,
                              const std::string& model_name = "");

// The cameras of every lens of PRESET, in order; lenses of one image circle
// (a Vuze's eight) are fitted once.
std::vector<PresetCamera> PresetLensCameras(const CameraPreset& preset,
                                            const PresetResolution& resolution,
                                            const std::string& model_name = "");

// Why MODEL_NAME cannot start the lenses of PRESET (not one of the
// whole-field lens models, registry.h's SphereModels but EQUIRECTANGULAR, or
// a preset of stitched panoramas), or "" (also for an empty name: the
// preset's).
std::string PresetLensModelError(const CameraPreset& preset,
                                 const std::string& model_name);

// cam_from_rig of lens LENS (lens 0 is the rig frame).
Eigen::Quaterniond PresetCamFromRigRotation(const CameraPreset& preset,
                                            int lens);
Eigen::Vector3d PresetCamFromRigTranslation(const CameraPreset& preset,
                                            int lens);

// rig_configurator's rig_config.json for the preset at the resolution: one
// rig, lens 0 the reference sensor, every lens with its camera model
// (MODEL_NAME, empty: the preset's) and parameters and (except lens 0) its
// nominal cam_from_rig. Images are named as the preset stores them after
// splitting: "FOLDER/NAME" with the folders
// LENS_FOLDERS (empty: the preset's own), or NAME<file_suffix> for files
// per lens.
std::string PresetRigConfigJson(const CameraPreset& preset,
                                const PresetResolution& resolution,
                                const std::vector<std::string>& lens_folders =
                                    {},
                                const std::string& model_name = "");

// What `colmap rig_preset` is asked: a camera and a resolution, as given on
// the command line. RESOLUTION is a name of the preset or "WxH"; without it,
// IMAGE_WIDTH and IMAGE_HEIGHT (both or neither); without either, the
// preset's first resolution.
struct RigPresetRequest {
  std::string camera;
  std::string resolution;
  int image_width = 0;
  int image_height = 0;
  // The lenses' starting model (empty: the preset's).
  std::string camera_model;
};

struct ResolvedPreset {
  const CameraPreset* preset = nullptr;
  PresetResolution resolution;
  std::string model_name;  // the lenses' starting model
};

// Checks the request once; throws std::invalid_argument naming the bad
// option (an unknown camera lists the known ones, a resolution the preset
// lacks lists its resolutions). camera "list" is not a preset: the caller
// lists them (PresetListText) instead.
ResolvedPreset ResolveRigPreset(const RigPresetRequest& request);

// One line per preset: name, description, its resolutions.
std::string PresetListText();

}  // namespace sphera
