// `colmap sphere_undistorter --input_path MODEL --image_path IMAGES
//     --output_path WORKSPACE [--face_size N] [--fov_deg D] [--overlap_deg D]
//     [--faces front,right,back,left,up,down] [--output_type COLMAP]
//     [--splatting 0|1] [--max_invalid_ratio R]
//     [--num_patch_match_src_images N] [--image_format jpg|png]
//     [--jpeg_quality Q]`: turns every registered image of MODEL into
// perspective PINHOLE views (cube faces for panoramas and wide-angle lenses)
// and writes a COLMAP dense workspace, or with --splatting 1 the
// Gaussian-splatting layout (controllers/sphere_undistortion.h).
#pragma once

namespace colmap {

int RunSphereUndistorter(int argc, char** argv);

}  // namespace colmap
