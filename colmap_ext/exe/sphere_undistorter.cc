#include "colmap_ext/exe/sphere_undistorter.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/util/file.h"
#include "colmap/util/logging.h"
#include "colmap_ext/controllers/sphere_undistortion.h"

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>

namespace colmap {

int RunSphereUndistorter(int argc, char** argv) {
  std::filesystem::path input_path;
  std::filesystem::path image_path;
  std::filesystem::path output_path;
  SphereUndistorterOptions export_options;

  OptionManager options;
  options.AddRequiredOption("input_path", &input_path);
  options.AddRequiredOption("image_path", &image_path);
  options.AddRequiredOption("output_path", &output_path);
  options.AddDefaultOption("face_size",
                           &export_options.face_size,
                           "cube face side in pixels; 0 = automatic");
  options.AddDefaultOption("fov_deg", &export_options.fov_deg);
  options.AddDefaultOption("overlap_deg", &export_options.overlap_deg);
  options.AddDefaultOption("faces", &export_options.faces);
  options.AddDefaultOption(
      "output_type", &export_options.output_type, "{COLMAP}");
  options.AddDefaultOption("splatting", &export_options.splatting);
  options.AddDefaultOption("max_invalid_ratio",
                           &export_options.max_invalid_ratio);
  options.AddDefaultOption("num_patch_match_src_images",
                           &export_options.num_patch_match_src_images);
  options.AddDefaultOption(
      "image_format", &export_options.image_format, "{jpg, png}");
  options.AddDefaultOption("jpeg_quality", &export_options.jpeg_quality);
  options.AddDefaultOption("mask_path", &export_options.mask_path);
  options.AddDefaultOption(
      "per_frame",
      &export_options.per_frame,
      "each direction of a rig frame from one lens, the nearest its axis");
  if (!options.Parse(argc, argv)) {
    return EXIT_FAILURE;
  }

  const std::string options_error = export_options.Check();
  if (!options_error.empty()) {
    LOG(ERROR) << "sphere_undistorter: " << options_error;
    return EXIT_FAILURE;
  }
  for (const auto& [name, path] : {std::make_pair("input_path", input_path),
                                   std::make_pair("image_path", image_path)}) {
    if (!ExistsDir(path)) {
      LOG(ERROR) << "sphere_undistorter: " << name << ": " << path.string()
                 << " is not a folder";
      return EXIT_FAILURE;
    }
  }

  try {
    Reconstruction reconstruction;
    try {
      reconstruction.Read(input_path);
    } catch (const std::exception& error) {
      throw std::invalid_argument("cannot read the model " +
                                  input_path.string() + ": " + error.what());
    }
    const SphereExportSummary summary =
        ExportPerspectiveWorkspace(reconstruction,
                                   image_path.string(),
                                   output_path.string(),
                                   export_options);
    LOG(INFO) << "sphere_undistorter: " << summary.num_input_images
              << " images in, " << summary.num_views << " views written, "
              << summary.num_points3D << " points, "
              << summary.num_observations << " observations, "
              << summary.num_bytes << " bytes written, " << summary.seconds
              << " s -> " << output_path.string();
  } catch (const std::exception& error) {
    LOG(ERROR) << "sphere_undistorter: " << error.what();
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace colmap
