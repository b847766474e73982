#include "colmap_ext/exe/command_line_paths.h"

#include <filesystem>
#include <fstream>
#include <set>
#include <utility>

namespace colmap {

CommandLinePaths::CommandLinePaths(std::string command,
                                   const int argc,
                                   const char* const* argv)
    : command_(std::move(command)) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--", 0) != 0) {
      continue;
    }
    Option option;
    const size_t equals = arg.find('=');
    if (equals != std::string::npos) {
      option.name = arg.substr(0, equals);
      option.value = arg.substr(equals + 1);
      option.has_value = true;
    } else {
      option.name = arg;
      option.has_value = i + 1 < argc;
      option.value = option.has_value ? argv[i + 1] : "";
    }
    options_.push_back(std::move(option));
  }
}

std::vector<std::string> CommandLinePaths::ValuesOf(
    const std::string& name) const {
  std::vector<std::string> values;
  for (const Option& option : options_) {
    if (option.name == "--" + name && option.has_value) {
      values.push_back(option.value);
    }
  }
  return values;
}

std::string CommandLinePaths::MissingDatabaseError() const {
  static const std::set<std::string> kCreating = {
      "feature_extractor", "feature_importer", "database_creator",
      "automatic_reconstructor", "gui"};
  if (kCreating.count(command_)) {
    return "";
  }
  std::vector<std::string> paths = ValuesOf("database_path");
  // A project file (--project_path) names its database in a line
  // `database_path=PATH`.
  for (const std::string& project : ValuesOf("project_path")) {
    std::ifstream file(project);
    std::string line;
    while (std::getline(file, line)) {
      const std::string key = "database_path=";
      const size_t start = line.find_first_not_of(" \t");
      if (start != std::string::npos &&
          line.compare(start, key.size(), key) == 0) {
        std::string path = line.substr(start + key.size());
        path.erase(path.find_last_not_of(" \t\r") + 1);
        paths.push_back(path);
      }
    }
  }
  for (const std::string& path : paths) {
    std::error_code error;
    if (!std::filesystem::exists(path, error)) {
      return "database " + path +
             " does not exist (feature_extractor creates a database)";
    }
    if (std::filesystem::is_regular_file(path, error) &&
        std::filesystem::file_size(path, error) == 0) {
      return "database " + path +
             " is empty (feature_extractor fills a database)";
    }
  }
  return "";
}

std::string CommandLinePaths::MissingPaths() const {
  static const std::set<std::string> kCommandsCreatingOutput = {
      "calibration_importer", "dual_fisheye_splitter", "image_undistorter",
      "rig_preset", "sphere_bundle_adjuster", "sphere_undistorter"};
  const bool creates_output = kCommandsCreatingOutput.count(command_) > 0;
  const std::string kPath = "_path";
  const std::string kOutputPath = "output_path";
  std::string missing;
  for (const Option& option : options_) {
    const std::string& name = option.name;
    std::error_code error;
    if (name.size() < kPath.size() + 2 ||
        name.compare(name.size() - kPath.size(), kPath.size(), kPath) != 0 ||
        option.value.empty() || std::filesystem::exists(option.value, error)) {
      continue;
    }
    // An output path in an existing folder is one the command would create.
    if (creates_output && name.size() >= kOutputPath.size() + 2 &&
        name.compare(name.size() - kOutputPath.size(), kOutputPath.size(),
                     kOutputPath) == 0 &&
        std::filesystem::is_directory(
            std::filesystem::absolute(option.value, error).parent_path(),
            error)) {
      continue;
    }
    missing += (missing.empty() ? "paths that do not exist: " : ", ") +
               name + " " + option.value;
  }
  return missing;
}

}  // namespace colmap
