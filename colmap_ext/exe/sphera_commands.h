// SPHERA's commands in colmap's command table (colmap/exe/colmap.cc calls
// SpheraCommands() once): each is declared in its own header beside this one
// and parses its options, then calls library code in controllers/.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace colmap {

using SpheraCommandFunc = int (*)(int argc, char** argv);

// (name, function) of every SPHERA command, in the order `colmap help` lists
// them after COLMAP's own.
std::vector<std::pair<std::string, SpheraCommandFunc>> SpheraCommands();

}  // namespace colmap
