#include "colmap_ext/exe/dual_fisheye_splitter.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/util/logging.h"
#include "colmap_ext/controllers/dual_fisheye_splitting.h"

#include <cstdlib>
#include <exception>

namespace colmap {

int RunDualFisheyeSplitter(int argc, char** argv) {
  DualFisheyeSplittingOptions splitting;
  // --input_path is required unless --front_path and --back_path are given,
  // which OptionManager's required options cannot say; Check() does.
  OptionManager options;
  options.AddDefaultOption("input_path",
                           &splitting.input_path,
                           "side-by-side raw frames, or with lens_suffixes "
                           "one file per lens (or with a --camera that "
                           "stores one file per lens: its files)");
  options.AddDefaultOption(
      "front_path", &splitting.front_path, "the front lens's files (lens0)");
  options.AddDefaultOption(
      "back_path", &splitting.back_path, "the back lens's files (lens1)");
  options.AddRequiredOption("output_path", &splitting.output_path);
  options.AddDefaultOption("image_list_path",
                           &splitting.image_list_path,
                           "only these files of input_path (names relative "
                           "to it, one a line)");
  options.AddDefaultOption("lens_suffixes",
                           &splitting.lens_suffixes,
                           "\"s0,s1\": input_path holds NAME<s0>.EXT of lens0 "
                           "and NAME<s1>.EXT of lens1");
  options.AddDefaultOption(
      "lens_names", &splitting.lens_names, "left,right lens folders");
  options.AddDefaultOption("circles",
                           &splitting.circles,
                           "\"cx,cy,r;cx,cy,r\" image circles of the left "
                           "and right lens in lens image pixels (may reach "
                           "past the image's edges); empty = detect");
  options.AddDefaultOption("camera",
                           &splitting.camera,
                           "a camera preset (rig_preset --camera list): its "
                           "circles and rig config");
  options.AddDefaultOption("black_level",
                           &splitting.black_level,
                           "intensity (8-bit scale) at or below which a "
                           "pixel is black");
  options.AddDefaultOption("camera_model",
                           &splitting.camera_model,
                           "camera of both lenses in rig_config.json "
                           "(with --camera: the model its lenses start "
                           "from)");
  options.AddDefaultOption("camera_params",
                           &splitting.camera_params,
                           "its parameters, comma-separated");
  options.AddDefaultOption("jpeg_quality", &splitting.jpeg_quality);
  options.AddDefaultOption("flat_field", &splitting.flat_field,
                           "estimate each lens's light fall-off towards the "
                           "rim of its circle from its images and divide it "
                           "out");
  options.AddDefaultOption("allow_incomplete_frames",
                           &splitting.allow_incomplete_frames,
                           "write the one lens of a frame whose other lens "
                           "file is missing, instead of refusing");
  if (!options.Parse(argc, argv)) {
    return EXIT_FAILURE;
  }
  try {
    SplitDualFisheyeFrames(splitting);
  } catch (const std::exception& error) {
    LOG(ERROR) << "dual_fisheye_splitter: " << error.what();
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace colmap
