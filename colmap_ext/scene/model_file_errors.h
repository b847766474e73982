// Errors of the model readers that name the file they come from.
#pragma once

#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace colmap {

// Runs read(), which reads the model file at `path`. Whatever it throws
// leaves as std::runtime_error "PATH: WHAT" (a truncated file, a value that
// does not parse, a reference to a missing camera or frame), so that the
// command can report it in one line and exit instead of aborting.
template <typename Read>
void ReadModelFile(const std::filesystem::path& path, Read&& read) {
  try {
    read();
  } catch (const std::exception& error) {
    throw std::runtime_error(path.string() + ": " + error.what());
  }
}

}  // namespace colmap
