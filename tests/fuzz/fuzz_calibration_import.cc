// libFuzzer target: the calibration importers (calibration/calibration_io.h)
// on any bytes. The first byte picks the format (Kalibr, OpenCV, OCamCalib,
// Basalt, or detection from the content); the rest is the file's content.
// A CalibrationError is the expected outcome of a bad file; any other
// exception, a crash, a leak or undefined behaviour is not, and neither is an
// imported camera that its own model's checks refuse.
#include <cstddef>
#include <cstdint>
#include <string>

#include "calibration/calibration_io.h"
#include "camera_models/registry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const sphera::CalibrationFormat kFormats[] = {
      sphera::CalibrationFormat::kKalibr, sphera::CalibrationFormat::kOpenCV,
      sphera::CalibrationFormat::kOCamCalib,
      sphera::CalibrationFormat::kBasalt, sphera::CalibrationFormat::kAuto};
  sphera::CalibrationImportOptions options;
  options.format = kFormats[data[0] % 5];
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    const sphera::ImportedCalibration calibration =
        sphera::ImportCalibrationText(text, "fuzz_input", options);
    for (const sphera::ImportedCamera& camera : calibration.cameras) {
      if (!sphera::CheckParams(camera.model_id, camera.params, camera.width,
                               camera.height)
               .empty()) {
        __builtin_trap();
      }
      if (camera.cam_from_rig_rotation &&
          (std::abs(camera.cam_from_rig_rotation->norm() - 1) > 1e-9 ||
           !camera.cam_from_rig_translation.allFinite())) {
        __builtin_trap();
      }
    }
    sphera::RigConfigJson(calibration);
    sphera::CamerasText(calibration);
  } catch (const sphera::CalibrationError&) {
  }
  return 0;
}
