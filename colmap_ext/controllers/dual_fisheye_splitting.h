// The frames of a dual-fisheye camera as one image per lens, its mask and a
// rig config, for `colmap dual_fisheye_splitter` (the command parses these
// options and calls SplitDualFisheyeFrames). The image work itself (circles,
// the frame check, the split) is image/dual_fisheye_split.h.
//
// A frame comes in one of three forms:
//   side by side  every image file below input_path (or those of
//                 image_list_path) is [lens0 | lens1] (Insta360, Ricoh
//                 Theta); the frame's NAME is its path relative to
//                 input_path.
//   two folders   front_path holds lens0's files and back_path lens1's
//                 (GoPro Fusion: FR/GPFR0003.JPG, BK/GPBK0003.JPG); a front
//                 and a back file are one frame when their names differ
//                 only by the cameras's lens tag (found from the names
//                 themselves: the difference most pairs of names share,
//                 "FR"/"BK" here; none when both folders use the same
//                 names). NAME is the front file's path with its tag
//                 removed (GP0003.JPG).
//   suffixes      input_path holds both lenses' files, NAME<s0>.EXT and
//                 NAME<s1>.EXT with lens_suffixes "s0,s1" (IMG_7_0.jpg,
//                 IMG_7_1.jpg); NAME.EXT is the frame's NAME (IMG_7.jpg).
// A camera preset that stores one file per lens (`camera` vuze:
// NAME_1.JPG ... NAME_8.JPG in input_path) has nothing to split: each file
// is cut to its lens's circle (the preset's at the files' size) and written
// as OUT/images/NAME_k.JPG with OUT/masks/NAME_k.JPG.png, beside the
// preset's rig config (its lenses found by those suffixes) and circles.txt.
// Outputs, in the layout of `colmap rig_configurator`:
//   OUT/images/<lens>/NAME      the lens image, pixels copied exactly, those
//                               outside the circle black; NAME's format
//   OUT/masks/<lens>/NAME.png   255 inside the image circle, 0 outside
//   OUT/rig_config.json         lens1 = lens0 turned 180 degrees about y
//                               (with `camera`, the preset's config)
//   OUT/circles.txt             "<lens> cx cy r", one line per lens, after
//                               a '#' comment line (as the renderer's)
// The image circles are `circles`, those of the camera preset `camera`
// (calibration/camera_presets.h) at the frames' size, or detected in every
// frame (DetectImageCircle) and the median taken per lens. All frames are read
// and checked (readable, one size, DualFisheyeFrameError, each frame's two
// lens files, no existing output) before anything is written; every file is
// written under a temporary name and renamed when all are written, so a
// failure leaves nothing behind.
#pragma once

#include <filesystem>
#include <string>

namespace colmap {

struct DualFisheyeSplittingOptions {
  // Side-by-side frames, or with lens_suffixes the lenses' files.
  std::filesystem::path input_path;
  // One folder per lens (both or neither; not with input_path).
  std::filesystem::path front_path;
  std::filesystem::path back_path;
  // "s0,s1": the file name endings (before the extension) of lens0's and
  // lens1's files in input_path.
  std::string lens_suffixes;
  std::filesystem::path output_path;
  // Only these files of input_path (names relative to it, one a line).
  std::filesystem::path image_list_path;
  // The lenses' folders under images/ and masks/, "lens0,lens1".
  std::string lens_names = "lens0,lens1";
  // "cx,cy,r;cx,cy,r" in lens image pixels; empty: detect them.
  std::string circles;
  // A camera preset (rig_preset --camera list): its circles at the frames'
  // size (a size it does not know is refused) and its rig config (lens
  // poses, the starting model), in place of circles and camera_params; with
  // camera_model alone, the lenses start from that model fitted to the
  // preset's lens (rig_preset --camera_model).
  std::string camera;
  // Intensity (8-bit scale) at or below which a pixel is black: pixels this
  // dark inside the circle at its rim say nothing about the frame, and a
  // circle on a black surround is located to the pixel.
  int black_level = 10;
  // The camera of both lenses in rig_config.json (both or neither; with
  // camera, the model alone).
  std::string camera_model;
  std::string camera_params;
  int jpeg_quality = 95;
  // Each lens's light fall-off towards the rim of its circle is estimated
  // from its images and divided out (colmap_ext/image/flat_field.h).
  bool flat_field = false;
  // A frame with the file of one lens missing (two folders, suffixes) is
  // an error, unless this: then its one lens is written, and
  // `rig_configurator --allow_incomplete_frames 1` takes it.
  bool allow_incomplete_frames = false;

  // Throws std::invalid_argument naming the option when one is bad.
  void Check() const;
};

// Splits the frames OPTIONS name (see above). Throws (std::invalid_argument
// for bad input, std::runtime_error when a file cannot be read or written)
// with a message naming every bad frame; nothing is then written.
void SplitDualFisheyeFrames(const DualFisheyeSplittingOptions& options);

}  // namespace colmap
