// libFuzzer target: COLMAP's reader of rig_configurator's JSON file as SPHERA
// patches it (a bad config is an error naming the file and the camera; a
// lens given by its field of view and image circle is fitted). The
// input is the file's content. Whatever the reader throws is an expected
// outcome; a crash, a leak or undefined behaviour is not (upstream wrote a
// rotation list of more than 4 numbers past the end of a 4-vector).
#include "colmap/scene/rig.h"

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("sphera_fuzz_rig_config_" + std::to_string(getpid()) + ".json");
  {
    // Streams retry writes that a signal interrupts (libFuzzer's timer).
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data),
              static_cast<std::streamsize>(size));
  }
  try {
    const std::vector<colmap::RigConfig> configs = colmap::ReadRigConfig(path);
    // What ApplyRigConfig relies on: one reference camera per rig, poses
    // with unit quaternions and finite translations, finite intrinsics (also
    // those fitted to a lens given by its field of view and image circle).
    for (const colmap::RigConfig& config : configs) {
      int num_ref = 0;
      for (const auto& camera : config.cameras) {
        num_ref += camera.ref_sensor;
        if (camera.camera) {
          for (const double param : camera.camera->params) {
            if (!std::isfinite(param)) __builtin_trap();
          }
        }
        if (camera.cam_from_rig &&
            (std::abs(camera.cam_from_rig->rotation().norm() - 1) > 1e-6 ||
             !camera.cam_from_rig->translation().allFinite())) {
          __builtin_trap();
        }
      }
      if (num_ref != 1) __builtin_trap();
    }
  } catch (const std::exception&) {
  }
  return 0;
}
