// How colmap's main runs the command it was given.
#pragma once

#include <functional>
#include <string>

namespace colmap {

// Runs `command_func(argc, argv)`, the command `command` of colmap's command
// table, and returns its exit status. A database the command would read
// that does not exist or is empty is refused before it runs; an exception
// that leaves the command, or one of its threads, is a one-line error
// "COMMAND: WHAT" and exit status 1, not an abort; after a failure, the
// paths of the command line that do not exist are named.
int RunCommand(const std::string& command,
               const std::function<int(int, char**)>& command_func,
               int argc,
               char** argv);

}  // namespace colmap
