// `colmap dual_fisheye_splitter --input_path RAW --output_path OUT
//     [--image_list_path LIST] [--lens_names lens0,lens1]
//     [--circles "cx,cy,r;cx,cy,r"] [--black_level 10]
//     [--camera_model NAME --camera_params LIST] [--jpeg_quality 95]`:
// splits the raw stills of a dual-fisheye camera (Insta360, Ricoh Theta; two
// image circles side by side, [lens0 | lens1]) into one image per lens and a
// mask of its image circle, in the layout of `colmap rig_configurator`:
//   OUT/images/<lens>/NAME      the lens's half of RAW/NAME, pixels copied
//                               exactly, those outside the circle black;
//                               the input's file format
//   OUT/masks/<lens>/NAME.png   255 inside the image circle, 0 outside
//                               (ImageReader.mask_path = OUT/masks)
//   OUT/rig_config.json         lens1 = lens0 turned 180 degrees about y
//   OUT/circles.txt             "<lens> cx cy r", one line per lens, after
//                               a '#' comment line (as the renderer's)
// NAME is the path of a raw frame relative to RAW (every image file below
// it, or those of LIST). The image circles (image/dual_fisheye_split.h for
// the pixel convention) are --circles, or detected in every frame and the
// per-lens median taken. All frames are read and checked (size, layout,
// black outside the circles, circles inside the lens images, no existing
// output) before anything is written; every file is written under a
// temporary name and renamed when all are written, so a failure leaves
// nothing behind.
#pragma once

namespace colmap {

int RunDualFisheyeSplitter(int argc, char** argv);

}  // namespace colmap
