// The fuzz input as a database file of its own in /dev/shm, for the targets
// that read databases (fuzz_database_check, fuzz_matching).
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace sphera_fuzz {

// Removes the database at `path` and SQLite's files beside it.
inline void RemoveDatabase(const std::string& path) {
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) {
    std::remove((path + suffix).c_str());
  }
}

// Writes the input to /dev/shm/sphera_NAME_PID.db (nothing beside it) and
// returns the path, or "" when the file cannot be written.
inline std::string WriteDatabaseInput(const std::string& name,
                                      const uint8_t* data, size_t size) {
  const std::string path = "/dev/shm/sphera_" + name + "_" +
                           std::to_string(getpid()) + ".db";
  RemoveDatabase(path);
  FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) {
    return "";
  }
  std::fwrite(data, 1, size, file);
  std::fclose(file);
  return path;
}

}  // namespace sphera_fuzz
