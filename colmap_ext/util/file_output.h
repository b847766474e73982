// Writing result files so that a failed or killed run never leaves a file
// that looks complete.
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

#include <unistd.h>

#include "synthetic/file_formats.h"

namespace colmap {

// The one way SPHERA's commands write their results: every file or folder is
// first written under a temporary name beside its final one ("NAME.tmp-PID"
// by default),
// and only Commit() gives them their names, so that a failed or killed run
// leaves what was there. Destroyed before Commit(), it removes what it wrote
// and the folders it created (when they are empty).
class StagedOutput {
 public:
  // Temporary names are final names + `suffix` (default ".tmp-PID").
  explicit StagedOutput(std::string suffix = "")
      : suffix_(suffix.empty() ? ".tmp-" + std::to_string(::getpid())
                               : std::move(suffix)) {}
  StagedOutput(const StagedOutput&) = delete;
  StagedOutput& operator=(const StagedOutput&) = delete;

  ~StagedOutput() {
    if (committed_) {
      return;
    }
    std::error_code ignored;
    for (const Entry& entry : staged_) {
      std::filesystem::remove_all(entry.temporary, ignored);
    }
    for (const std::filesystem::path& path : committed_paths_) {
      std::filesystem::remove_all(path, ignored);
    }
    for (auto folder = created_folders_.rbegin();
         folder != created_folders_.rend();
         ++folder) {
      std::filesystem::remove(*folder, ignored);  // only if empty
    }
  }

  // The temporary path under which the caller writes the file `path`
  // (creating the folders above it unless `create_folders` is false).
  std::filesystem::path Stage(const std::filesystem::path& path,
                              bool create_folders = true) {
    if (create_folders) {
      CreateFolders(path.parent_path());
    }
    staged_.push_back({TemporaryPath(path), path, false});
    return staged_.back().temporary;
  }

  // A temporary folder, created, that becomes `path` on Commit(): renamed if
  // `path` does not exist, else its entries are moved into `path`, where
  // only empty folders of the same names may stand.
  std::filesystem::path StageFolder(const std::filesystem::path& path) {
    CreateFolders(path.parent_path());
    const std::filesystem::path temporary = TemporaryPath(path);
    std::error_code error;
    if (!std::filesystem::create_directory(temporary, error) || error) {
      throw std::runtime_error("cannot create the folder " +
                               temporary.string() + ": " + error.message());
    }
    staged_.push_back({temporary, path, true});
    return temporary;
  }

  // Writes `bytes` as the file `path`.
  void Write(const std::filesystem::path& path, const std::string& bytes) {
    const std::filesystem::path temporary = Stage(path);
    std::ofstream file(temporary, std::ios::binary);
    file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    file.close();
    if (!file) {
      throw std::runtime_error("cannot write " + temporary.string() +
                               " (disk full? no permission?)");
    }
  }

  void Commit() {
    for (const Entry& entry : staged_) {
      if (entry.is_folder && std::filesystem::exists(entry.final_path)) {
        MoveEntries(entry.temporary, entry.final_path);
        continue;
      }
      std::error_code error;
      std::filesystem::rename(entry.temporary, entry.final_path, error);
      if (error) {
        throw std::runtime_error("cannot rename " + entry.temporary.string() +
                                 " to " + entry.final_path.string() + ": " +
                                 error.message());
      }
      committed_paths_.push_back(entry.final_path);
    }
    committed_ = true;
  }

 private:
  struct Entry {
    std::filesystem::path temporary;
    std::filesystem::path final_path;
    bool is_folder;
  };

  std::filesystem::path TemporaryPath(
      const std::filesystem::path& path) const {
    return path.string() + suffix_;
  }

  void MoveEntries(const std::filesystem::path& from,
                   const std::filesystem::path& to) {
    for (const auto& entry : std::filesystem::directory_iterator(from)) {
      const std::filesystem::path target = to / entry.path().filename();
      if (std::filesystem::exists(target)) {
        if (!std::filesystem::is_directory(target) ||
            !std::filesystem::is_empty(target)) {
          throw std::invalid_argument(target.string() +
                                      " appeared while writing");
        }
        std::filesystem::remove(target);
      }
      std::filesystem::rename(entry.path(), target);
      committed_paths_.push_back(target);
    }
    std::error_code ignored;
    std::filesystem::remove_all(from, ignored);
  }

  void CreateFolders(const std::filesystem::path& folder) {
    if (folder.empty() || std::filesystem::is_directory(folder)) {
      return;
    }
    CreateFolders(folder.parent_path());
    std::error_code error;
    std::filesystem::create_directory(folder, error);
    if (error) {
      throw std::runtime_error("cannot create the folder " + folder.string() +
                               ": " + error.message());
    }
    created_folders_.push_back(folder);
  }

  std::string suffix_;
  std::vector<Entry> staged_;
  std::vector<std::filesystem::path> committed_paths_;
  std::vector<std::filesystem::path> created_folders_;
  bool committed_ = false;
};

// Writes the files of one result into the folder `folder` with a
// StagedOutput, into a folder that must exist: files are (file name,
// write(file path)); a write throws on failure, and nothing of the result is
// then left.
inline void WriteFilesAtomically(
    const std::filesystem::path& folder,
    const std::vector<std::pair<
        std::string, std::function<void(const std::filesystem::path&)>>>&
        files) {
  // A fixed temporary name per file: a killed write leaves at most one
  // NAME.tmp beside each file, which the next write replaces.
  StagedOutput staged(".tmp");
  for (const auto& [name, write] : files) {
    write(staged.Stage(folder / name, /*create_folders=*/false));
  }
  staged.Commit();
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

using sphera::JsonList;

}  // namespace colmap
