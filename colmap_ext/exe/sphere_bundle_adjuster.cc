#include "colmap_ext/exe/sphere_bundle_adjuster.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/util/file.h"
#include "colmap/util/logging.h"
#include "colmap_ext/controllers/sphere_bundle_adjustment.h"

#include <cstdlib>
#include <exception>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>

namespace colmap {

int RunSphereBundleAdjuster(int argc, char** argv) {
  using Options = SphereBundleAdjustmentOptions;
  std::string input_path;
  std::string output_path;
  Options options;
  OptionManager option_manager;
  option_manager.AddRequiredOption("input_path", &input_path);
  option_manager.AddRequiredOption("output_path", &output_path);
  option_manager.AddDefaultEnumOption("mode", &options.mode,
                                      &SphereBundleAdjustmentModeToString,
                                      &SphereBundleAdjustmentModeFromString);
  option_manager.AddDefaultOption("tau_px", &options.tau_px);
  option_manager.AddDefaultOption("max_iterations", &options.max_iterations);
  option_manager.AddDefaultOption("refine_intrinsics",
                                  &options.refine_intrinsics);
  option_manager.AddDefaultEnumOption("residual", &options.residual,
                                      &SphereResidualTypeToString,
                                      &SphereResidualTypeFromString);
  option_manager.AddDefaultEnumOption("loss", &options.loss,
                                      &SphereBundleAdjustmentLossToString,
                                      &SphereBundleAdjustmentLossFromString);
  option_manager.AddDefaultOption("loss_scale_px", &options.loss_scale_px);
  option_manager.AddDefaultOption("min_observations_per_image",
                                  &options.min_observations_per_image);
  if (!option_manager.Parse(argc, argv)) {
    return EXIT_FAILURE;
  }

  std::string error = options.Check();
  if (!error.empty()) {
    LOG(ERROR) << "sphere_bundle_adjuster: " << error;
    return EXIT_FAILURE;
  }
  if (!ExistsDir(input_path)) {
    LOG(ERROR) << "--input_path: " << input_path << " is not a directory";
    return EXIT_FAILURE;
  }
  if (ExistsFile(output_path)) {
    LOG(ERROR) << "--output_path: " << output_path
               << " is a file, not a directory";
    return EXIT_FAILURE;
  }

  Reconstruction reconstruction;
  try {
    reconstruction.Read(input_path);
  } catch (const std::exception& exception) {
    LOG(ERROR) << "--input_path: cannot read the model " << input_path << ": "
               << exception.what();
    return EXIT_FAILURE;
  }

  SphereBundleAdjustmentSummary summary;
  if (!SphereBundleAdjust(options, &reconstruction, &summary, &error)) {
    LOG(ERROR) << "sphere_bundle_adjuster: " << error
               << "; nothing was written";
    return EXIT_FAILURE;
  }

  const bool camera_only = options.mode == Options::Mode::CAMERA_ONLY;
  std::ostringstream out;
  out << std::setprecision(6);
  out << "sphere_bundle_adjuster: mode " << options.mode << ", residual "
      << options.residual;
  if (camera_only) out << ", tau " << options.tau_px << " px";
  out << "\n  iterations:        " << summary.iterations
      << "\n  points:            " << summary.num_points_before << " -> "
      << summary.num_points_after
      << (camera_only ? " (reliable, re-triangulated)" : "")
      << "\n  observations:      " << summary.num_observations_before << " -> "
      << summary.num_observations_after
      << "\n  mean angular error: " << summary.mean_error_before_rad
      << " rad (" << summary.mean_error_before_px << " px) -> "
      << summary.mean_error_after_rad << " rad ("
      << summary.mean_error_after_px << " px)"
      << "\n  time:              " << summary.seconds << " s\n";
  std::cout << out.str() << std::flush;

  try {
    CreateDirIfNotExists(output_path, /*recursive=*/true);
    reconstruction.Write(output_path);
  } catch (const std::exception& exception) {
    LOG(ERROR) << "--output_path: cannot write " << output_path << ": "
               << exception.what();
    return EXIT_FAILURE;
  }
  std::cout << "  written to:        " << output_path << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace colmap
