#include "colmap_ext/exe/sphera_commands.h"

#include "colmap_ext/exe/calibration_importer.h"
#include "colmap_ext/exe/dual_fisheye_splitter.h"
#include "colmap_ext/exe/model_evaluator.h"
#include "colmap_ext/exe/rig_calibration.h"
#include "colmap_ext/exe/rig_check.h"
#include "colmap_ext/exe/rig_preset.h"
#include "colmap_ext/exe/sphere_bundle_adjuster.h"
#include "colmap_ext/exe/sphere_undistorter.h"
#include "colmap_ext/exe/strecha_importer.h"

namespace colmap {

std::vector<std::pair<std::string, SpheraCommandFunc>> SpheraCommands() {
  return {
      {"calibration_importer", &RunCalibrationImporter},
      {"dual_fisheye_splitter", &RunDualFisheyeSplitter},
      {"model_evaluator", &RunModelEvaluator},
      {"rig_calibration", &RunRigCalibration},
      {"rig_check", &RunRigCheck},
      {"rig_preset", &RunRigPreset},
      {"sphere_bundle_adjuster", &RunSphereBundleAdjuster},
      {"sphere_undistorter", &RunSphereUndistorter},
      {"strecha_importer", &RunStrechaImporter},
  };
}

}  // namespace colmap
