// `colmap dual_fisheye_splitter (--input_path RAW | --front_path FR
//     --back_path BK) --output_path OUT [--lens_suffixes s0,s1]
//     [--image_list_path LIST] [--lens_names lens0,lens1]
//     [--circles "cx,cy,r;cx,cy,r" | --camera PRESET] [--black_level 10]
//     [--camera_model NAME --camera_params LIST] [--jpeg_quality 95]
//     [--allow_incomplete_frames 0]`:
// the frames of a dual-fisheye camera (both circles side by side in one
// file, or one file per lens) as one image per lens, its mask, rig_config.json
// and circles.txt. What it reads and writes:
// controllers/dual_fisheye_splitting.h.
#pragma once

namespace colmap {

int RunDualFisheyeSplitter(int argc, char** argv);

}  // namespace colmap
