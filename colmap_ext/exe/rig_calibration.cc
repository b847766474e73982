#include "colmap_ext/exe/rig_calibration.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/util/file.h"
#include "colmap/util/logging.h"
#include "colmap_ext/controllers/rig_calibration.h"
#include "colmap_ext/util/file_output.h"

#include <exception>
#include <iostream>
#include <optional>
#include <string>

namespace colmap {

int RunRigCalibration(int argc, char** argv) {
  std::string input_path;
  std::string gt_path;
  std::string output_path;
  RigCalibrationOptions calibration_options;

  OptionManager options;
  options.AddRequiredOption("input_path", &input_path);
  options.AddDefaultOption("gt_path", &gt_path);
  options.AddDefaultOption("output_path", &output_path);
  options.AddDefaultOption(
      "radius_fraction", &calibration_options.radius_fraction,
      "Field of view and projection differences over the disc of this "
      "fraction of min(width, height) around the principal point.");
  if (!options.Parse(argc, argv)) {
    return EXIT_FAILURE;
  }
  if (const std::string error = calibration_options.Check(); !error.empty()) {
    LOG(ERROR) << "rig_calibration: " << error;
    return EXIT_FAILURE;
  }
  for (const auto& [name, path] :
       {std::make_pair("input_path", input_path),
        std::make_pair("gt_path", gt_path),
        std::make_pair("output_path", output_path)}) {
    if (!path.empty() && !ExistsDir(path)) {
      LOG(ERROR) << name << ": " << path << " is not a directory";
      return EXIT_FAILURE;
    }
  }

  try {
    Reconstruction model;
    model.Read(input_path);
    std::optional<Reconstruction> ground_truth;
    if (!gt_path.empty()) {
      ground_truth.emplace();
      ground_truth->Read(gt_path);
    }
    const RigCalibrationReport report = CalibrateRigs(
        model, ground_truth ? &*ground_truth : nullptr, calibration_options);
    std::cout << RigCalibrationText(report) << std::flush;
    if (!output_path.empty()) {
      WriteTextFilesAtomically(
          output_path, {{"rig_config.json", RigConfigJson(report)},
                        {"rig_calibration.json", RigCalibrationJson(report)}});
    }
  } catch (const std::exception& error) {
    LOG(ERROR) << "rig_calibration: " << input_path << ": " << error.what();
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace colmap
