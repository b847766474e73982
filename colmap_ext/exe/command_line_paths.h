// The paths a command line names, and which of them do not exist: said
// before a command that would create an empty database in place of a
// missing one, and after a command that failed.
#pragma once

#include <string>
#include <vector>

namespace colmap {

class CommandLinePaths {
 public:
  // The options of `colmap COMMAND ARGS` (argv[0] is the program) given as
  // `--NAME VALUE` or `--NAME=VALUE`.
  CommandLinePaths(std::string command, int argc, const char* const* argv);

  // Empty, or why the command cannot run: its --database_path (or the
  // database_path of its --project_path file) names a file that does not
  // exist or is empty, and the command only reads and adds to a database
  // (every command but feature_extractor, feature_importer,
  // database_creator, automatic_reconstructor and gui, which create one).
  // COLMAP would create an empty database there and then fail, leaving the
  // new file behind.
  std::string MissingDatabaseError() const;

  // Empty, or "paths that do not exist: --OPTION PATH, ..." for the options
  // named *_path whose value is not in the file system (said after the
  // command failed, whichever path made it fail). An *output_path in an
  // existing folder is not missing for the commands that create their
  // output (dual_fisheye_splitter, image_undistorter, rig_preset,
  // sphere_bundle_adjuster, sphere_undistorter); the others, such as
  // mapper, need it to exist.
  std::string MissingPaths() const;

 private:
  struct Option {
    std::string name;  // with its leading "--"
    std::string value;
    bool has_value = false;
  };
  std::vector<std::string> ValuesOf(const std::string& name) const;

  std::string command_;
  std::vector<Option> options_;
};

}  // namespace colmap
