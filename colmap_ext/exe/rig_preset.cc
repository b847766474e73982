#include "colmap_ext/exe/rig_preset.h"

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>

#include "calibration/camera_presets.h"
#include "colmap/controllers/option_manager.h"
#include "colmap/util/logging.h"
#include "colmap_ext/util/file_output.h"

namespace colmap {

int RunRigPreset(int argc, char** argv) {
  sphera::RigPresetRequest request;
  std::string output_path;
  OptionManager options;
  options.AddRequiredOption("camera",
                            &request.camera,
                            "a camera preset, or \"list\" to list them");
  options.AddDefaultOption(
      "output_path", &output_path, "the rig_config.json to write");
  options.AddDefaultOption("resolution",
                           &request.resolution,
                           "a resolution of the preset, by name or WxH "
                           "(the stored file's size); default: its first");
  options.AddDefaultOption("image_width",
                           &request.image_width,
                           "the stored file's width (with image_height)");
  options.AddDefaultOption("image_height", &request.image_height);
  options.AddDefaultOption("camera_model",
                           &request.camera_model,
                           "the lenses' starting model, fitted to the "
                           "preset's lens (default: the preset's)");
  if (!options.Parse(argc, argv)) {
    return EXIT_FAILURE;
  }
  if (request.camera == "list") {
    std::cout << sphera::PresetListText();
    return EXIT_SUCCESS;
  }
  try {
    const sphera::ResolvedPreset resolved = sphera::ResolveRigPreset(request);
    if (output_path.empty()) {
      throw std::invalid_argument("--output_path: the rig_config.json to "
                                  "write is missing");
    }
    const std::filesystem::path path(output_path);
    const std::filesystem::path folder =
        std::filesystem::absolute(path).parent_path();
    if (!std::filesystem::is_directory(folder)) {
      throw std::invalid_argument("--output_path " + output_path +
                                  ": the folder " + folder.string() +
                                  " does not exist");
    }
    if (std::filesystem::is_directory(path)) {
      throw std::invalid_argument("--output_path " + output_path +
                                  " is a folder; give the file to write");
    }
    const sphera::CameraPreset& preset = *resolved.preset;
    WriteTextFilesAtomically(
        folder,
        {{path.filename().string(),
          sphera::PresetRigConfigJson(preset, resolved.resolution, {},
                                      resolved.model_name)}});
    std::cout << "rig_preset: " << preset.name << " ("
              << sphera::LensStorageName(preset.storage) << "), "
              << resolved.resolution.name << " " << resolved.resolution.width
              << "x" << resolved.resolution.height << ": "
              << preset.lenses.size() << " lens(es), " << resolved.model_name
              << "; circles " << resolved.resolution.source << "; poses "
              << preset.source << "\nimages: "
              << (preset.storage == sphera::LensStorage::kFilePerLens
                      ? "NAME_1.JPG ... in one folder, as the camera names "
                        "them"
                      : preset.storage ==
                                sphera::LensStorage::kEquirectangular
                            ? "the panoramas under pano/"
                            : "lens0/NAME, lens1/NAME, as "
                              "dual_fisheye_splitter --camera " +
                                  preset.name + " writes them")
              << "\nwrote " << output_path << "\n";
  } catch (const std::exception& error) {
    LOG(ERROR) << "rig_preset: " << error.what();
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace colmap
