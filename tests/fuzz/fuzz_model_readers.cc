// libFuzzer target: COLMAP's text and binary model readers as SPHERA
// patches them (a damaged file is an error naming it). The input's first
// byte picks the format and which of the five files of a valid model
// (SPHERA_FUZZ_MODEL/{text,binary}, made by scripts/fuzz.sh) it replaces;
// the rest is that file's content. Whatever the reader throws is an
// expected outcome; a crash, a leak or undefined behaviour is not.
#include "colmap/scene/reconstruction.h"

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

const char* const kFiles[] = {"rigs", "cameras", "frames", "images",
                              "points3D"};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) {
    return 0;
  }
  static const std::filesystem::path model = [] {
    const char* env = std::getenv("SPHERA_FUZZ_MODEL");
    return std::filesystem::path(env ? env : "fuzz_model");
  }();
  static const std::filesystem::path work =
      std::filesystem::temp_directory_path() /
      ("sphera_fuzz_model_" + std::to_string(getpid()));
  const bool binary = data[0] & 1;
  const std::string file =
      std::string(kFiles[(data[0] >> 1) % 5]) + (binary ? ".bin" : ".txt");
  std::filesystem::remove_all(work);
  std::filesystem::copy(model / (binary ? "binary" : "text"), work);
  {
    std::ofstream out(work / file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1),
              static_cast<std::streamsize>(size - 1));
  }
  colmap::Reconstruction reconstruction;
  try {
    if (binary) {
      reconstruction.ReadBinary(work);
    } else {
      reconstruction.ReadText(work);
    }
  } catch (const std::exception&) {
  }
  return 0;
}
