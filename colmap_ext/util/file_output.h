// Writing result files so that a failed or killed run never leaves a file
// that looks complete, and the JSON number lists those files hold.
#pragma once

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace colmap {

// Writes the files of one result into the folder `folder`: each first under
// its name + ".tmp", and only when all are written are they renamed to their
// names, so that a run killed while writing (or a write that fails) leaves
// what was there. files: (file name, write(file path)); a write throws on
// failure, and the temporary files are then removed.
inline void WriteFilesAtomically(
    const std::filesystem::path& folder,
    const std::vector<std::pair<
        std::string, std::function<void(const std::filesystem::path&)>>>&
        files) {
  std::vector<std::filesystem::path> written;
  try {
    for (const auto& [name, write] : files) {
      written.push_back(folder / (name + ".tmp"));
      write(written.back());
    }
  } catch (...) {
    std::error_code ignored;
    for (const auto& tmp : written) {
      std::filesystem::remove(tmp, ignored);
    }
    throw;
  }
  for (size_t i = 0; i < files.size(); ++i) {
    std::filesystem::rename(written[i], folder / files[i].first);
  }
}

// The same for files whose whole text is at hand: (file name, text).
inline void WriteTextFilesAtomically(
    const std::filesystem::path& folder,
    const std::vector<std::pair<std::string, std::string>>& texts) {
  std::vector<std::pair<std::string,
                        std::function<void(const std::filesystem::path&)>>>
      files;
  for (const auto& [name, text] : texts) {
    files.emplace_back(name, [&text = text](const std::filesystem::path& tmp) {
      std::ofstream file(tmp, std::ios::trunc);
      file << text;
      file.close();
      if (!file) {
        throw std::runtime_error("cannot write " + tmp.string());
      }
    });
  }
  WriteFilesAtomically(folder, files);
}

// "[v0, v1, ...]" with every value to full double precision.
inline std::string JsonList(const std::vector<double>& values) {
  std::ostringstream out;
  out << std::setprecision(17) << "[";
  for (size_t i = 0; i < values.size(); ++i) {
    out << (i ? ", " : "") << values[i];
  }
  out << "]";
  return out.str();
}

}  // namespace colmap
