// libFuzzer target: the camera presets' lookup and `colmap rig_preset`'s
// option checks (calibration/camera_presets.h) on any text. The input's
// lines are the option values: --camera, --resolution, --image_width,
// --image_height (the sizes read as OptionManager reads an int: a number,
// else 0), then a name looked up as a resolution of every preset, then
// --camera_model. An
// std::invalid_argument is the expected outcome of bad values; any other
// exception, a crash or undefined behaviour is not, and neither is an
// accepted request whose circles, lens cameras or rig config break the
// preset's own rules.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "calibration/camera_presets.h"
#include "camera_models/registry.h"

namespace {

int ParseInt(const std::string& text) {
  std::istringstream stream(text);
  int value = 0;
  stream >> value;
  return stream.fail() ? 0 : value;
}

// A resolution that was accepted: it is the preset's, with a circle per
// lens inside its lens image, and (once per preset and size) its lens
// cameras pass their checks and its rig config is written.
void CheckResolved(const sphera::ResolvedPreset& resolved) {
  const sphera::CameraPreset& preset = *resolved.preset;
  const sphera::PresetResolution& resolution = resolved.resolution;
  const Eigen::Vector2i size = sphera::LensImageSize(preset, resolution);
  if (size.x() <= 0 || size.y() <= 0) __builtin_trap();
  if (preset.storage != sphera::LensStorage::kEquirectangular) {
    if (resolution.circles.size() != preset.lenses.size()) __builtin_trap();
    for (const sphera::PresetCircle& circle : resolution.circles) {
      if (!(circle.cx > 0 && circle.cx < size.x() && circle.cy > 0 &&
            circle.cy < size.y() && circle.r > 0)) {
        __builtin_trap();
      }
    }
  }
  static std::set<std::pair<std::string, std::string>> checked;
  if (!checked.insert({preset.name, resolution.name + " " +
                                        resolved.model_name})
           .second ||
      checked.size() > 64) {
    return;
  }
  for (const sphera::PresetCamera& camera : sphera::PresetLensCameras(
           preset, resolution, resolved.model_name)) {
    if (!sphera::CheckParams(camera.model_id, camera.params, camera.width,
                             camera.height)
             .empty()) {
      __builtin_trap();
    }
  }
  sphera::PresetRigConfigJson(preset, resolution, {}, resolved.model_name);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> lines(6);
  size_t line = 0;
  for (size_t i = 0; i < size && line < lines.size(); ++i) {
    if (data[i] == '\n') {
      ++line;
    } else {
      lines[line] += static_cast<char>(data[i]);
    }
  }
  sphera::RigPresetRequest request;
  request.camera = lines[0];
  request.resolution = lines[1];
  request.image_width = ParseInt(lines[2]);
  request.image_height = ParseInt(lines[3]);
  request.camera_model = lines[5];
  try {
    CheckResolved(sphera::ResolveRigPreset(request));
  } catch (const std::invalid_argument&) {
  }
  for (const sphera::CameraPreset& preset : sphera::CameraPresets()) {
    try {
      sphera::FindPresetResolution(preset, lines[4]);
    } catch (const std::invalid_argument&) {
    }
  }
  return 0;
}
