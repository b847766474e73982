// A check of a COLMAP database file before COLMAP opens it for writing.
#pragma once

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

// Empty, or why `colmap COMMAND ARGS` cannot run: its --database_path (or
// the database_path of its --project_path file) names a file that does not
// exist or is empty, and the command only reads and
// adds to a database (every command but feature_extractor,
// feature_importer, database_creator, automatic_reconstructor and gui,
// which create one). COLMAP would create an empty database there and then
// fail, leaving the new file behind.
std::string MissingDatabaseError(const std::string& command, int argc,
                                 const char* const* argv);

// Removes from the database at `path` (if it exists), in one transaction,
// the cameras that no image uses, together with the rigs of which such a
// camera is the only sensor and that no frame uses: what a feature
// extraction killed midway leaves (it writes an image's camera and rig
// before the image). `keep_camera_id` (--ImageReader.existing_camera_id,
// a camera made beforehand for the images to come) is kept. Returns the
// number of cameras removed; throws like CheckDatabaseFile when the file
// cannot be changed.
int RemoveUnusedCameras(const std::filesystem::path& path,
                        int64_t keep_camera_id);

// Empty, or why the matching that just wrote to the database at `path`
// leaves it with no image pair a mapper can use (no two-view geometry
// with inlier matches): fewer than two images, no pair selected, pairs
// whose raw matches all fell short of `min_num_inliers`, or pairs with
// enough raw matches that all failed geometric verification (the sign of
// a wrong camera model or parameters). The file is only read.
std::string NoVerifiedPairError(const std::filesystem::path& path,
                                int min_num_inliers);

// Empty, or "paths that do not exist: --OPTION PATH, ..." for the options
// of ARGS named *_path whose value is not in the file system (said after
// `colmap COMMAND ARGS` failed, whichever path made it fail). An
// *output_path in an existing folder is not missing for the commands that
// create their output (dual_fisheye_splitter, image_undistorter,
// rig_preset, sphere_bundle_adjuster, sphere_undistorter); the others, such
// as mapper,
// need it to exist.
std::string MissingPaths(const std::string& command, int argc,
                         const char* const* argv);

}  // namespace colmap
