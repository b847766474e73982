// `colmap strecha_importer --input_path DIR --output_path MODEL
//     [--output_type BIN|TXT]`: Strecha's ground-truth cameras as a model
// (controllers/strecha_import.h).
#pragma once

namespace colmap {

int RunStrechaImporter(int argc, char** argv);

}  // namespace colmap
