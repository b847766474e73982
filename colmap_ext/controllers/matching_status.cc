#include "colmap_ext/controllers/matching_status.h"

#include "colmap/estimators/two_view_geometry.h"
#include "colmap/util/logging.h"
#include "colmap_ext/scene/database_check.h"

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace colmap {

int MatchingExitStatus(const OptionManager& options) {
  const std::string error = NoVerifiedPairError(
      *options.database_path, options.two_view_geometry->min_num_inliers);
  if (!error.empty()) {
    LOG(ERROR) << error;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

std::shared_ptr<Database> OpenDatabaseToMatch(
    const std::filesystem::path& path) {
  auto database = Database::Open(path);
  if (database->NumImages() == 0 || database->NumKeypoints() == 0) {
    throw std::runtime_error(
        "database " + path.string() + ": no " +
        (database->NumImages() == 0 ? "images" : "keypoints") +
        " to match (run feature_extractor on it first)");
  }
  return database;
}

}  // namespace colmap
