// A matching run without anything to match, or without a result a mapper
// can use, is an error that says why.
#pragma once

#include "colmap/controllers/option_manager.h"
#include "colmap/scene/database.h"

#include <filesystem>
#include <memory>

namespace colmap {

// EXIT_SUCCESS when the matching that just wrote to the database of
// `options` leaves an image pair a mapper can use; otherwise logs why not
// (NoVerifiedPairError) and returns EXIT_FAILURE: a mapper would find
// nothing to start from.
int MatchingExitStatus(const OptionManager& options);

// The database at `path`, opened for matching; throws std::runtime_error
// "database PATH: no images to match ..." (or keypoints) when it has
// nothing to match, instead of a run that does nothing and succeeds.
std::shared_ptr<Database> OpenDatabaseToMatch(
    const std::filesystem::path& path);

}  // namespace colmap
