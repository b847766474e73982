#include "colmap_ext/exe/calibration_importer.h"

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "calibration/calibration_io.h"
#include "colmap/controllers/option_manager.h"
#include "colmap/util/file.h"
#include "colmap/util/logging.h"
#include "colmap_ext/util/file_output.h"

namespace colmap {
namespace {

std::string Fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

void PrintCamera(const sphera::ImportedCamera& camera) {
  std::cout << camera.name << ": " << camera.source_model << ", "
            << camera.width << "x" << camera.height << " -> "
            << camera.model_name;
  if (camera.fit) {
    std::cout << " (fitted over " << camera.fit->num_samples
              << " rays up to " << Fixed(camera.fit->max_angle_deg, 1)
              << " deg from the axis: median error "
              << Fixed(camera.fit->median_error_px, 3) << " px, max "
              << Fixed(camera.fit->max_error_px, 3) << " px";
    if (camera.fit->num_not_visible > 0) {
      std::cout << "; " << camera.fit->num_not_visible
                << " rays not seen by the fitted model";
    }
    std::cout << ")";
  } else {
    std::cout << " (exact)";
  }
  std::cout << "\n  " << sphera::ImageReaderOptions(camera) << "\n";
}

}  // namespace

int RunCalibrationImporter(int argc, char** argv) {
  std::string input_path;
  std::string format = "auto";
  std::string camera_model;
  std::string output_path;
  double half_field_deg = 0;

  OptionManager options;
  options.AddRequiredOption("input_path", &input_path);
  options.AddDefaultOption("format", &format,
                           "{auto, kalibr, opencv, ocamcalib, basalt}");
  options.AddDefaultOption("camera_model", &camera_model,
                           "a model of ours to convert every camera to");
  options.AddDefaultOption("half_field_deg", &half_field_deg,
                           "the lens's half field of view (a circular "
                           "fisheye's image circle): a fit uses only rays "
                           "within it; 0: the whole image frame");
  options.AddDefaultOption("output_path", &output_path);
  if (!options.Parse(argc, argv)) {
    return EXIT_FAILURE;
  }
  // A folder that does not exist yet is made when there is something to
  // write (command_line_paths.cc checks that its parent exists).
  if (!output_path.empty() && ExistsPath(output_path) &&
      !ExistsDir(output_path)) {
    LOG(ERROR) << "output_path: " << output_path << " is not a directory";
    return EXIT_FAILURE;
  }
  try {
    sphera::CalibrationImportOptions import_options;
    import_options.format = sphera::CalibrationFormatFromName(format);
    import_options.camera_model = camera_model;
    import_options.half_field_deg = half_field_deg;
    const sphera::ImportedCalibration calibration =
        sphera::ImportCalibrationFile(input_path, import_options);

    std::cout << input_path << ": "
              << sphera::CalibrationFormatName(calibration.format) << ", "
              << calibration.cameras.size() << " camera(s)\n";
    for (const sphera::ImportedCamera& camera : calibration.cameras) {
      PrintCamera(camera);
    }
    for (const std::string& note : calibration.notes) {
      std::cout << "note: " << note << "\n";
    }
    const bool rig = calibration.cameras.size() > 1;
    if (rig) {
      std::cout << "rig: " << calibration.cameras.size() << " cameras, "
                << calibration.cameras[0].name
                << " is the rig frame; images of camera NAME under NAME/\n";
    }
    if (output_path.empty()) {
      if (rig) std::cout << sphera::RigConfigJson(calibration);
      return EXIT_SUCCESS;
    }
    std::vector<std::pair<std::string, std::string>> files = {
        {"cameras.txt", sphera::CamerasText(calibration)}};
    if (rig) files.emplace_back("rig_config.json", RigConfigJson(calibration));
    std::filesystem::create_directory(output_path);
    WriteTextFilesAtomically(output_path, files);
    for (const auto& file : files) {
      std::cout << "wrote "
                << (std::filesystem::path(output_path) / file.first).string()
                << "\n";
    }
  } catch (const std::exception& error) {
    LOG(ERROR) << "calibration_importer: " << error.what();
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace colmap
