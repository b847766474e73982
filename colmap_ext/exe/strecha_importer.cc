#include "colmap_ext/exe/strecha_importer.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/util/file.h"
#include "colmap/util/logging.h"
#include "colmap/util/string.h"
#include "colmap_ext/controllers/strecha_import.h"

namespace colmap {

int RunStrechaImporter(int argc, char** argv) {
  std::string input_path;
  std::string output_path;
  std::string output_type = "TXT";

  OptionManager options;
  options.AddRequiredOption("input_path", &input_path);
  options.AddRequiredOption("output_path", &output_path);
  options.AddDefaultOption("output_type", &output_type, "{BIN, TXT}");
  if (!options.Parse(argc, argv)) {
    return EXIT_FAILURE;
  }

  if (!ExistsDir(input_path)) {
    LOG(ERROR) << "input_path: " << input_path << " is not a directory";
    return EXIT_FAILURE;
  }
  if (!ExistsDir(output_path)) {
    LOG(ERROR) << "output_path: " << output_path << " is not a directory";
    return EXIT_FAILURE;
  }
  StringToUpper(&output_type);
  if (output_type != "BIN" && output_type != "TXT") {
    LOG(ERROR) << "output_type: must be BIN or TXT, got " << output_type;
    return EXIT_FAILURE;
  }
  try {
    const Reconstruction reconstruction = ReadStrechaCameras(input_path);
    if (output_type == "BIN") {
      reconstruction.WriteBinary(output_path);
    } else {
      reconstruction.WriteText(output_path);
    }
    LOG(INFO) << "Imported " << reconstruction.NumImages() << " cameras";
  } catch (const std::exception& error) {
    LOG(ERROR) << "strecha_importer: " << error.what();
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace colmap
