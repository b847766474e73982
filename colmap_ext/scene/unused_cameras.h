// What a feature extraction killed midway leaves in a database: cameras
// (and rigs) of images it never wrote. Unlike database_check, this writes.
#pragma once

#include <cstdint>
#include <filesystem>

namespace colmap {

// Removes from the database at `path` (if it exists), in one transaction,
// the cameras that no image uses, together with the rigs of which such a
// camera is the only sensor and that no frame uses: what a feature
// extraction killed midway leaves (it writes an image's camera and rig
// before the image). `keep_camera_id` (--ImageReader.existing_camera_id,
// a camera made beforehand for the images to come) is kept. Returns the
// number of cameras removed; throws std::runtime_error "database PATH: ..."
// when the file cannot be changed.
int RemoveUnusedCameras(const std::filesystem::path& path,
                        int64_t keep_camera_id);

// Before a feature extraction into the database at `path`: refuses a
// damaged database (CheckDatabaseFile), then removes the cameras an
// interrupted run left (RemoveUnusedCameras) and says how many.
void RemoveCamerasOfInterruptedExtraction(const std::filesystem::path& path,
                                          int64_t keep_camera_id);

}  // namespace colmap
