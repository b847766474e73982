#include "colmap_ext/scene/unused_cameras.h"

#include "colmap/util/types.h"
#include "colmap/util/logging.h"
#include "colmap/util/version.h"
#include "colmap_ext/scene/database_check.h"

#include <cstdlib>
#include <stdexcept>
#include <string>

#include <sqlite3.h>

namespace colmap {
namespace {

constexpr int kCameraSensor = static_cast<int>(SensorType::CAMERA);

}  // namespace

int RemoveUnusedCameras(const std::filesystem::path& path,
                        const int64_t keep_camera_id) {
  if (!HoldsDatabase(path)) {
    return 0;
  }
  sqlite3* db = nullptr;
  const auto fail = [&](const std::string& what) {
    const std::string message = db ? sqlite3_errmsg(db) : "out of memory";
    sqlite3_close_v2(db);
    throw std::runtime_error("database " + path.string() + ": " + what +
                             ": " + message);
  };
  if (sqlite3_open_v2(path.string().c_str(), &db, SQLITE_OPEN_READWRITE,
                      nullptr) != SQLITE_OK) {
    fail("cannot be opened");
  }
  const auto count = [](void* n, int, char** values, char**) {
    *static_cast<int*>(n) = std::atoi(values[0]);
    return 0;
  };
  int tables = 0;
  sqlite3_exec(db,
               "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND "
               "name IN ('cameras', 'images', 'rigs', 'rig_sensors', 'frames');",
               count, &tables, nullptr);
  if (tables != 5) {  // not (yet) a database of COLMAP 4's rigs and frames
    sqlite3_close_v2(db);
    return 0;
  }
  const std::string camera = std::to_string(kCameraSensor);
  const std::string unused =
      "SELECT camera_id FROM cameras WHERE camera_id != " +
      std::to_string(keep_camera_id) +
      " AND camera_id NOT IN (SELECT camera_id FROM images)"
      " AND camera_id NOT IN (SELECT sensor_id FROM rig_sensors"
      "   WHERE sensor_type = " + camera + ")"
      " AND camera_id NOT IN (SELECT ref_sensor_id FROM rigs"
      "   WHERE ref_sensor_type = " + camera +
      "   AND (rig_id IN (SELECT rig_id FROM frames)"
      "     OR rig_id IN (SELECT rig_id FROM rig_sensors)))";
  int removed = 0;
  const std::string sql =
      "BEGIN IMMEDIATE;"
      "CREATE TEMP TABLE sphera_unused AS " + unused + ";"
      "SELECT count(*) FROM sphera_unused;"
      "DELETE FROM rigs WHERE ref_sensor_type = " + camera +
      "  AND ref_sensor_id IN (SELECT camera_id FROM sphera_unused);"
      "DELETE FROM cameras WHERE camera_id IN"
      "  (SELECT camera_id FROM sphera_unused);"
      "DROP TABLE sphera_unused;"
      "COMMIT;";
  if (sqlite3_exec(db, sql.c_str(), count, &removed, nullptr) != SQLITE_OK) {
    sqlite3_exec(db, "ROLLBACK;", nullptr, nullptr, nullptr);
    fail("cannot remove the cameras no image uses");
  }
  sqlite3_close_v2(db);
  return removed;
}

void RemoveCamerasOfInterruptedExtraction(const std::filesystem::path& path,
                                          const int64_t keep_camera_id) {
  CheckDatabaseFile(path, GetDatabaseVersionNumber());
  if (const int removed = RemoveUnusedCameras(path, keep_camera_id);
      removed > 0) {
    LOG(INFO) << "Removed " << removed
              << " camera(s) that no image uses (left by an interrupted "
                 "feature extraction)";
  }
}

}  // namespace colmap
