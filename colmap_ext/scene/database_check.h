// Read-only checks of a COLMAP database file: before COLMAP opens it for
// writing, and after a matching run.
#pragma once

#include "colmap/scene/database.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace colmap {

// Checks the existing COLMAP database at `path` for the damage that would
// make COLMAP's readers abort, read past a blob or silently use garbage, and
// throws std::runtime_error "database PATH: WHAT" (naming the table, the
// row and what is wrong) on the first problem found. The file is opened
// read only and is never changed. Checked: that SQLite can read every page
// (quick_check); that it is a COLMAP database of a format this program
// knows (`format_version`: its own PRAGMA user_version; a newer major
// version is refused), with all the core tables and their columns; camera
// models, sizes and parameters (count and finite values); that images,
// keypoints, descriptors, matches, two-view geometries, rigs and frames
// refer to rows that exist; that every blob has the size its rows and
// columns declare, keypoints 2, 4 or 6 columns, SIFT descriptors 128, as
// many descriptors as keypoints, matches (raw and verified) of keypoints
// that exist, two-view configurations known. Tables of later schema
// versions may be missing (an older database, which COLMAP migrates). The
// cost is one read of the file. A file that does not exist or is empty (a
// new database) passes.
void CheckDatabaseFile(const std::filesystem::path& path, int format_version);

// Database::Open: the database at `path` from the last registered of
// `factories` that opens it; when none does, throws the last one's reason,
// prefixed with "database PATH: " unless the reason names it already.
std::shared_ptr<Database> OpenDatabase(
    const std::vector<Database::Factory>& factories,
    const std::filesystem::path& path);

// False for a file that does not exist or is empty: a database COLMAP is
// about to create.
bool HoldsDatabase(const std::filesystem::path& path);

// Empty, or why the matching that just wrote to the database at `path`
// leaves it with no image pair a mapper can use (no two-view geometry
// with inlier matches): fewer than two images, no pair selected, pairs
// whose raw matches all fell short of `min_num_inliers`, or pairs with
// enough raw matches that all failed geometric verification (the sign of
// a wrong camera model or parameters). The file is only read.
std::string NoVerifiedPairError(const std::filesystem::path& path,
                                int min_num_inliers);

// "the verified matches of images ID1 and ID2 refer to keypoint POINT2D_IDX
// of image IMAGE_ID, which has NUM_KEYPOINTS keypoints: ..." (the database's
// matches belong to other keypoints: damaged, or features extracted again
// after matching; using the others would build on garbage).
std::string MatchOfMissingKeypointError(uint32_t image_id1,
                                        uint32_t image_id2,
                                        uint32_t image_id,
                                        uint32_t point2D_idx,
                                        size_t num_keypoints);

}  // namespace colmap
