// `colmap rig_preset --camera NAME --output_path rig_config.json
//     [--resolution NAME|WxH | --image_width W --image_height H]`:
// the rig config of a common 360° camera (its lenses' directions, nominal
// offsets and starting intrinsics at that resolution), as rig_configurator
// reads it; `--camera list` lists the presets. The presets and their
// sources: calibration/camera_presets.h.
#pragma once

namespace colmap {

int RunRigPreset(int argc, char** argv);

}  // namespace colmap
