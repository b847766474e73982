// libFuzzer target: SPHERA's check of a COLMAP database file
// (colmap_ext/scene/database_check), on the input written as a file.
//
// The check and the camera parameter check it calls are instrumented, the
// rest of COLMAP (its camera model table) linked from the build.
#include "colmap_ext/scene/database_check.h"

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path =
      "/dev/shm/sphera_fuzz_database_" + std::to_string(getpid()) + ".db";
  FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) {
    return 0;
  }
  std::fwrite(data, 1, size, file);
  std::fclose(file);
  try {
    colmap::CheckDatabaseFile(path, 4020000);
  } catch (const std::runtime_error&) {
    // A named error is the expected outcome for most inputs.
  }
  std::remove(path.c_str());
  std::remove((path + "-wal").c_str());
  std::remove((path + "-shm").c_str());
  return 0;
}
