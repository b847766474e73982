#include "colmap_ext/exe/rig_check.h"

#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>

#include "colmap/controllers/option_manager.h"
#include "colmap/util/logging.h"
#include "colmap_ext/controllers/rig_direction_check.h"

namespace colmap {

int RunRigCheck(int argc, char** argv) {
  RigCheckOptions check_options;
  OptionManager options;
  options.AddDatabaseOptions();
  options.AddDefaultOption("max_angle_deg", &check_options.max_angle_deg,
                           "a lens direction off by more is an error");
  options.AddDefaultOption("max_ray_error_deg",
                           &check_options.max_ray_error_deg,
                           "matched rays of two lenses fit their rotation "
                           "within this angle (room for their parallax)");
  options.AddDefaultOption("min_num_inliers", &check_options.min_num_inliers,
                           "fewer fitting rays in a lens pair of a frame is "
                           "no measurement");
  if (!options.Parse(argc, argv)) {
    return EXIT_FAILURE;
  }
  try {
    const RigCheckReport report =
        CheckRigDirectionsInDatabaseFile(*options.database_path,
                                         check_options);
    std::cout << "rig_check: " << RigCheckText(report);
    if (report.num_measured_pairs == 0) {
      std::cout << "rig_check: no lens pair inside a frame has enough "
                   "verified matches: every lens unchecked (match the "
                   "images of each frame with each other, e.g. "
                   "exhaustive_matcher)\n";
      return EXIT_SUCCESS;
    }
    int num_contradicted = 0;
    for (const LensCheck& lens : report.lenses) {
      if (lens.direction.status ==
          sphera::LensDirectionStatus::kContradicted) {
        LOG(ERROR) << "rig_check: "
                   << LensContradictionText(lens, check_options);
        ++num_contradicted;
      }
    }
    if (num_contradicted > 0) {
      LOG(ERROR) << "rig_check: " << num_contradicted
                 << " lens direction(s) of the rig config contradict the "
                    "images; fix rig_config.json and run rig_configurator "
                    "again before mapping";
      return EXIT_FAILURE;
    }
    std::cout << "rig_check: the rig config agrees with the images\n";
  } catch (const std::exception& error) {
    LOG(ERROR) << "rig_check: " << error.what();
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace colmap
