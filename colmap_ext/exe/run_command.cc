#include "colmap_ext/exe/run_command.h"

#include "colmap/util/logging.h"
#include "colmap_ext/exe/command_line_paths.h"

#include <cstdio>
#include <cstdlib>
#include <exception>

namespace colmap {
namespace {

// An exception that leaves one of the command's threads (a database write
// of the feature writer, a matcher's read) ends the program like one of the
// command itself, not with an abort.
void EndThreadExceptionsWithTheirMessage(const std::string& command) {
  static std::string running_command;
  running_command = command;
  std::set_terminate([] {
    try {
      if (std::current_exception()) {
        std::rethrow_exception(std::current_exception());
      }
    } catch (const std::exception& error) {
      std::fprintf(stderr, "%s: %s\n", running_command.c_str(), error.what());
      std::fflush(stderr);
      std::_Exit(EXIT_FAILURE);
    } catch (...) {
    }
    std::abort();
  });
}

}  // namespace

int RunCommand(const std::string& command,
               const std::function<int(int, char**)>& command_func,
               const int argc,
               char** argv) {
  EndThreadExceptionsWithTheirMessage(command);
  const CommandLinePaths paths(command, argc, argv);
  if (const std::string error = paths.MissingDatabaseError(); !error.empty()) {
    LOG(ERROR) << command << ": " << error;
    return EXIT_FAILURE;
  }
  // Bad input (a damaged model file, a value that does not parse) is a
  // one-line error and a non-zero exit, not an abort.
  int status = EXIT_FAILURE;
  try {
    status = command_func(argc, argv);
  } catch (const std::exception& error) {
    LOG(ERROR) << command << ": " << error.what();
  }
  if (status != EXIT_SUCCESS) {
    // Whatever the command said, a path it was given that does not exist
    // is named.
    if (const std::string missing = paths.MissingPaths(); !missing.empty()) {
      LOG(ERROR) << command << ": " << missing;
    }
  }
  return status;
}

}  // namespace colmap
