// libFuzzer target: SPHERA's check of a COLMAP database file
// (colmap_ext/scene/database_check), on the input written as a file.
//
// The check and the camera parameter check it calls are instrumented, the
// rest of COLMAP (its camera model table) linked from the build.
#include "colmap_ext/scene/database_check.h"
#include "tests/fuzz/database_input.h"

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path =
      sphera_fuzz::WriteDatabaseInput("fuzz_database", data, size);
  if (path.empty()) {
    return 0;
  }
  try {
    colmap::CheckDatabaseFile(path, 4020000);
  } catch (const std::runtime_error&) {
    // A named error is the expected outcome for most inputs.
  }
  sphera_fuzz::RemoveDatabase(path);
  return 0;
}
