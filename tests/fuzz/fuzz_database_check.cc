// libFuzzer target: SPHERA's check of a COLMAP database file
// (colmap_ext/scene/database_check), on the input written as a file.
//
// Built on its own, without COLMAP's libraries: the three camera model
// queries the check makes are answered here by a table of three models of
// 3, 4 and 5 parameters.
#include "colmap/sensor/models.h"
#include "colmap_ext/scene/database_check.h"

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace colmap {

bool ExistsCameraModelWithId(CameraModelId model_id) {
  const int id = static_cast<int>(model_id);
  return id >= 0 && id < 3;
}

size_t CameraModelNumParams(CameraModelId model_id) {
  return 3 + static_cast<int>(model_id);
}

const std::string& CameraModelIdToName(CameraModelId) {
  static const std::string kName = "FUZZ_MODEL";
  return kName;
}

}  // namespace colmap

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
