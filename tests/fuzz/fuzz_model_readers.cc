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
#include <iterator>
#include <string>
#include <vector>

namespace {

const char* const kFiles[] = {"rigs", "cameras", "frames", "images",
                              "points3D"};

// The valid model's files, {text, binary} x kFiles, read once.
const std::vector<std::string>& ValidFiles() {
  static const std::vector<std::string> files = [] {
    const char* env = std::getenv("SPHERA_FUZZ_MODEL");
    const std::filesystem::path model(env ? env : "fuzz_model");
    std::vector<std::string> contents;
    for (const char* format : {"text", "binary"}) {
      for (const char* name : kFiles) {
        std::ifstream file(model / format /
                               (std::string(name) +
                                (format[0] == 't' ? ".txt" : ".bin")),
                           std::ios::binary);
        contents.emplace_back(std::istreambuf_iterator<char>(file),
                              std::istreambuf_iterator<char>());
      }
    }
    return contents;
  }();
  return files;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) {
    return 0;
  }
  static const std::filesystem::path work = [] {
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() /
        ("sphera_fuzz_model_" + std::to_string(getpid()));
    std::filesystem::create_directories(path);
    return path;
  }();
  const bool binary = data[0] & 1;
  const size_t damaged = (data[0] >> 1) % 5;
  // Written with streams, which retry writes that a signal interrupts
  // (libFuzzer's timer), unlike std::filesystem::copy.
  for (size_t i = 0; i < 5; ++i) {
    std::ofstream out(
        work / (std::string(kFiles[i]) + (binary ? ".bin" : ".txt")),
        std::ios::binary | std::ios::trunc);
    if (i == damaged) {
      out.write(reinterpret_cast<const char*>(data + 1),
                static_cast<std::streamsize>(size - 1));
    } else {
      out << ValidFiles()[(binary ? 5 : 0) + i];
    }
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
