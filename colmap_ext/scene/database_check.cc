#include "colmap_ext/scene/database_check.h"

#include "colmap/scene/camera.h"
#include "colmap/sensor/models.h"
#include "colmap/util/logging.h"
#include "colmap_ext/scene/camera_params_error.h"
#include "colmap/util/types.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <sqlite3.h>

namespace colmap {
namespace {

// What COLMAP's readers need of each table (columns of later schema
// versions, which COLMAP adds when it migrates an older file, are not
// required).
const std::map<std::string, std::vector<std::string>>& RequiredColumns() {
  static const std::map<std::string, std::vector<std::string>> kColumns = {
      {"cameras", {"camera_id", "model", "width", "height", "params"}},
      {"images", {"image_id", "name", "camera_id"}},
      {"keypoints", {"image_id", "rows", "cols", "data"}},
      {"descriptors", {"image_id", "rows", "cols", "data"}},
      {"matches", {"pair_id", "rows", "cols", "data"}},
      {"two_view_geometries", {"pair_id", "rows", "cols", "data", "config"}},
      {"rigs", {"rig_id", "ref_sensor_id", "ref_sensor_type"}},
      {"rig_sensors", {"rig_id", "sensor_id", "sensor_type"}},
      {"frames", {"frame_id", "rig_id"}},
      {"frame_data", {"frame_id", "data_id", "sensor_id", "sensor_type"}},
  };
  return kColumns;
}

// Tables that every COLMAP database since the first has: one of them
// without the others is a damaged file, not an older one.
const char* const kCoreTables[] = {
    "cameras", "images", "keypoints", "descriptors", "matches"};

constexpr int kSiftType = 0;  // FeatureExtractorType::SIFT
constexpr int kCameraSensor = static_cast<int>(SensorType::CAMERA);
constexpr int kMaxConfig = 9;  // TwoViewGeometry::CALIBRATED_RIG

// How far outside its image a keypoint may lie, in pixels: detectors place
// keypoints up to about half a pixel outside the pixel grid (COLMAP's pixel
// centres are at +0.5); any farther is damage, not a feature at the border.
double KeypointMargin(int64_t size) { return 2.0 + 0.01 * size; }

class ReadOnlyDatabase {
 public:
  explicit ReadOnlyDatabase(const std::filesystem::path& path)
      : name_("database " + path.string()) {
    if (sqlite3_open_v2(path.string().c_str(), &db_, SQLITE_OPEN_READONLY,
                        nullptr) != SQLITE_OK) {
      Fail(std::string("cannot be opened: ") +
           (db_ ? sqlite3_errmsg(db_) : "out of memory"));
    }
  }
  ~ReadOnlyDatabase() { sqlite3_close_v2(db_); }
  ReadOnlyDatabase(const ReadOnlyDatabase&) = delete;
  ReadOnlyDatabase& operator=(const ReadOnlyDatabase&) = delete;

  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(name_ + ": " + what);
  }

  // Runs `sql`, calling row(statement) for each result row.
  void Query(const std::string& sql,
             const std::function<void(sqlite3_stmt*)>& row) const {
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
      const std::string message = sqlite3_errmsg(db_);
      sqlite3_finalize(stmt);
      Fail(DescribeSqliteError(message));
    }
    int rc;
    while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) {
      try {
        row(stmt);
      } catch (...) {
        sqlite3_finalize(stmt);
        throw;
      }
    }
    const std::string message = sqlite3_errmsg(db_);
    sqlite3_finalize(stmt);
    if (rc != SQLITE_DONE) {
      Fail(DescribeSqliteError(message));
    }
  }

 private:
  static std::string DescribeSqliteError(const std::string& message) {
    if (message.find("not a database") != std::string::npos) {
      return "is not an SQLite database (" + message + ")";
    }
    if (message.find("malformed") != std::string::npos) {
      return "is damaged: " + message +
             " (a truncated or partly overwritten file)";
    }
    if (message.find("locked") != std::string::npos) {
      return "is locked by another process (" + message + ")";
    }
    return "cannot be read: " + message;
  }

  std::string name_;
  sqlite3* db_ = nullptr;
};

int64_t Int(sqlite3_stmt* stmt, int col) {
  return sqlite3_column_int64(stmt, col);
}

// The bytes of a blob column; NULL counts as 0.
int64_t Bytes(sqlite3_stmt* stmt, int col) {
  return sqlite3_column_type(stmt, col) == SQLITE_NULL
             ? 0
             : sqlite3_column_bytes(stmt, col);
}

std::string Text(sqlite3_stmt* stmt, int col) {
  const unsigned char* text = sqlite3_column_text(stmt, col);
  return text ? reinterpret_cast<const char*>(text) : "";
}

template <typename T>
std::string Str(const T& value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

class DatabaseChecker {
 public:
  DatabaseChecker(const std::filesystem::path& path, int format_version)
      : db_(path), format_version_(format_version) {}

  void Run() {
    CheckPages();
    CheckVersion();
    if (!CheckTables()) {
      return;  // A new database: no tables yet.
    }
    CheckCameras();
    CheckImages();
    CheckFeatures();
    CheckPairs("matches", false);
    if (tables_.count("two_view_geometries")) {
      CheckPairs("two_view_geometries", true);
    }
    CheckRigsAndFrames();
  }

 private:
  void CheckPages() {
    std::string result;
    db_.Query("PRAGMA quick_check(1);",
              [&](sqlite3_stmt* stmt) { result = Text(stmt, 0); });
    if (result != "ok") {
      std::replace(result.begin(), result.end(), '\n', ' ');
      db_.Fail("is damaged (SQLite quick_check: " + result.substr(0, 200) +
               "): a truncated or partly overwritten file");
    }
  }

  void CheckVersion() {
    int64_t version = 0;
    db_.Query("PRAGMA user_version;",
              [&](sqlite3_stmt* stmt) { version = Int(stmt, 0); });
    // COLMAP writes MAJOR * 1000000 + MINOR * 10000 + PATCH * 100 + DEV.
    if (version / 1000000 > format_version_ / 1000000) {
      db_.Fail("was written by COLMAP " + Str(version / 1000000) + "." +
               Str(version / 10000 % 100) +
               ", whose database format this program (format " +
               Str(format_version_ / 1000000) + "." +
               Str(format_version_ / 10000 % 100) + ") does not know");
    }
  }

  // False for a database without tables.
  bool CheckTables() {
    db_.Query("SELECT name FROM sqlite_master WHERE type = 'table';",
              [&](sqlite3_stmt* stmt) { tables_.insert(Text(stmt, 0)); });
    if (tables_.empty()) {
      return false;
    }
    std::vector<std::string> missing;
    for (const char* table : kCoreTables) {
      if (!tables_.count(table)) {
        missing.push_back(table);
      }
    }
    if (missing.size() == std::size(kCoreTables)) {
      std::string names;
      for (const auto& table : tables_) {
        names += (names.empty() ? "" : ", ") + table;
      }
      db_.Fail("is not a COLMAP database (its tables: " + names + ")");
    }
    if (!missing.empty()) {
      db_.Fail("lacks the table '" + missing.front() +
               "' that every COLMAP database has (a damaged file)");
    }
    for (const auto& [table, columns] : RequiredColumns()) {
      if (!tables_.count(table)) {
        continue;
      }
      std::set<std::string> present;
      db_.Query("PRAGMA table_info(" + table + ");",
                [&](sqlite3_stmt* stmt) { present.insert(Text(stmt, 1)); });
      for (const auto& column : columns) {
        if (!present.count(column)) {
          db_.Fail("table '" + table + "' lacks the column '" + column + "'");
        }
      }
    }
    return true;
  }

  void CheckCameras() {
    db_.Query(
        "SELECT camera_id, model, width, height, params FROM cameras;",
        [&](sqlite3_stmt* stmt) {
          const int64_t camera_id = Int(stmt, 0);
          const std::string row = "cameras row " + Str(camera_id) + ": ";
          const int64_t model = Int(stmt, 1);
          if (model < 0 || model > 1000000 ||
              !ExistsCameraModelWithId(static_cast<CameraModelId>(model))) {
            db_.Fail(row + "unknown camera model id " + Str(model));
          }
          const auto model_id = static_cast<CameraModelId>(model);
          if (Int(stmt, 2) <= 0 || Int(stmt, 3) <= 0) {
            db_.Fail(row + "image size " + Str(Int(stmt, 2)) + "x" +
                     Str(Int(stmt, 3)) + " is not positive");
          }
          const size_t num_params = CameraModelNumParams(model_id);
          const int64_t bytes = Bytes(stmt, 4);
          if (bytes != static_cast<int64_t>(num_params * sizeof(double))) {
            db_.Fail(row + CameraModelIdToName(model_id) + " has " +
                     Str(num_params) + " parameters, but the params blob " +
                     "holds " + Str(bytes) + " bytes, not " +
                     Str(num_params * sizeof(double)));
          }
          std::vector<double> params(num_params);
          if (num_params > 0) {
            std::memcpy(params.data(), sqlite3_column_blob(stmt, 4),
                        num_params * sizeof(double));
          }
          for (size_t i = 0; i < num_params; ++i) {
            if (!std::isfinite(params[i])) {
              db_.Fail(row + "parameter " + Str(i + 1) + " of " +
                       CameraModelIdToName(model_id) + " is " +
                       Str(params[i]));
            }
          }
          // Parameters that contradict the image size (an equirectangular
          // w,h other than width x height) or their model's validity.
          Camera camera;
          camera.model_id = model_id;
          camera.width = static_cast<size_t>(Int(stmt, 2));
          camera.height = static_cast<size_t>(Int(stmt, 3));
          camera.params = std::move(params);
          if (const std::string error = CameraParamsError(camera);
              !error.empty()) {
            db_.Fail(row + error);
          }
          cameras_[camera_id] = {Int(stmt, 2), Int(stmt, 3)};
        });
  }

  void CheckImages() {
    db_.Query("SELECT image_id, name, camera_id FROM images;",
              [&](sqlite3_stmt* stmt) {
                const int64_t image_id = Int(stmt, 0);
                const std::string name = Text(stmt, 1);
                if (!cameras_.count(Int(stmt, 2))) {
                  db_.Fail("image " + Str(image_id) + " (" + name +
                           ") refers to camera " + Str(Int(stmt, 2)) +
                           ", which is not in the cameras table");
                }
                if (images_.count(image_id)) {
                  db_.Fail("image " + Str(image_id) + " has two rows (" +
                           images_.at(image_id) + " and " + name + ")");
                }
                if (const auto [it, inserted] = image_ids_.emplace(name, image_id);
                    !inserted) {
                  db_.Fail("images " + Str(it->second) + " and " +
                           Str(image_id) + " have the same name " + name);
                }
                images_.emplace(image_id, name);
                image_cameras_.emplace(image_id, Int(stmt, 2));
              });
  }

  std::string ImageName(int64_t image_id) const {
    return "image " + Str(image_id) + " (" + images_.at(image_id) + ")";
  }

  // `table` row of `image_id` or of its pair: a prefix of the messages.
  std::string RowOfImage(const std::string& table, int64_t image_id) const {
    if (!images_.count(image_id)) {
      db_.Fail(table + " of image " + Str(image_id) +
               ", which is not in the images table");
    }
    return table + " of " + ImageName(image_id) + ": ";
  }

  void CheckMatrix(const std::string& row, int64_t rows, int64_t cols,
                   int64_t bytes, int64_t bytes_per_value) const {
    if (rows < 0 || cols < 0) {
      db_.Fail(row + "negative size " + Str(rows) + "x" + Str(cols));
    }
    if (rows * cols * bytes_per_value != bytes) {
      db_.Fail(row + Str(rows) + "x" + Str(cols) + " values need " +
               Str(rows * cols * bytes_per_value) + " bytes, the blob holds " +
               Str(bytes));
    }
  }

  // Every value finite (location, scale and orientation or affine shape),
  // every location inside the image of the image's camera, give or take
  // KeypointMargin: a NaN or a far-off keypoint would make matching and
  // mapping compute on garbage (or never converge).
  void CheckKeypointValues(const std::string& row, int64_t image_id,
                           int64_t rows, int64_t cols,
                           const char* data) const {
    const auto& [width, height] = cameras_.at(image_cameras_.at(image_id));
    const double margin_x = KeypointMargin(width);
    const double margin_y = KeypointMargin(height);
    for (int64_t k = 0; k < rows; ++k) {
      float values[6];  // the blob need not be aligned
      std::memcpy(values, data + k * cols * sizeof(float),
                  cols * sizeof(float));
      for (int64_t c = 0; c < cols; ++c) {
        if (!std::isfinite(values[c])) {
          db_.Fail(row + "keypoint " + Str(k) + " has the value " +
                   Str(values[c]) + " in column " + Str(c + 1));
        }
      }
      const double x = values[0], y = values[1];
      if (x < -margin_x || x > width + margin_x || y < -margin_y ||
          y > height + margin_y) {
        db_.Fail(row + "keypoint " + Str(k) + " at (" + Str(x) + ", " +
                 Str(y) + ") lies outside the " + Str(width) + "x" +
                 Str(height) + " image of camera " +
                 Str(image_cameras_.at(image_id)));
      }
    }
  }

  void CheckFeatures() {
    auto& num_keypoints = num_keypoints_;
    db_.Query("SELECT image_id, rows, cols, data FROM keypoints;",
              [&](sqlite3_stmt* stmt) {
                const int64_t image_id = Int(stmt, 0);
                const std::string row = RowOfImage("keypoints", image_id);
                const int64_t rows = Int(stmt, 1), cols = Int(stmt, 2);
                if (rows > 0 && cols != 2 && cols != 4 && cols != 6) {
                  db_.Fail(row + Str(cols) +
                           " columns (a keypoint has 2, 4 or 6 values)");
                }
                CheckMatrix(row, rows, cols, Bytes(stmt, 3), sizeof(float));
                CheckKeypointValues(row, image_id, rows, cols,
                                    static_cast<const char*>(
                                        sqlite3_column_blob(stmt, 3)));
                num_keypoints[image_id] = rows;
              });
    std::set<std::string> columns;
    db_.Query("PRAGMA table_info(descriptors);",
              [&](sqlite3_stmt* stmt) { columns.insert(Text(stmt, 1)); });
    const std::string type = columns.count("type") ? "type" : "0";
    db_.Query(
        "SELECT image_id, rows, cols, data, " + type + " FROM descriptors;",
        [&](sqlite3_stmt* stmt) {
          const int64_t image_id = Int(stmt, 0);
          const std::string row = RowOfImage("descriptors", image_id);
          const int64_t rows = Int(stmt, 1), cols = Int(stmt, 2);
          CheckMatrix(row, rows, cols, Bytes(stmt, 3), 1);
          if (rows > 0 && Int(stmt, 4) == kSiftType && cols != 128) {
            db_.Fail(row + "SIFT descriptors of " + Str(cols) +
                     " values (they have 128)");
          }
          const auto keypoints = num_keypoints.find(image_id);
          if (keypoints != num_keypoints.end() && keypoints->second != rows) {
            db_.Fail(row + Str(rows) + " descriptors for " +
                     Str(keypoints->second) + " keypoints");
          }
        });
  }

  void CheckPairs(const std::string& table, bool geometries) {
    std::set<std::string> columns;
    db_.Query("PRAGMA table_info(" + table + ");",
              [&](sqlite3_stmt* stmt) { columns.insert(Text(stmt, 1)); });
    // Blob columns of two-view geometries and their sizes when set.
    std::vector<std::pair<std::string, int64_t>> blobs;
    if (geometries) {
      for (const auto& [column, size] :
           std::vector<std::pair<std::string, int64_t>>{
               {"F", 72}, {"E", 72}, {"H", 72}, {"qvec", 32}, {"tvec", 24}}) {
        if (columns.count(column)) {
          blobs.emplace_back(column, size);
        }
      }
    }
    std::string sql = "SELECT pair_id, rows, cols, data";
    sql += geometries ? ", config" : ", 0";
    for (const auto& blob : blobs) {
      sql += ", " + blob.first;
    }
    db_.Query(sql + " FROM " + table + ";", [&](sqlite3_stmt* stmt) {
      const int64_t pair_id = Int(stmt, 0);
      if (pair_id < 0) {
        db_.Fail(table + " row " + Str(pair_id) + ": negative pair id");
      }
      const auto [image_id1, image_id2] =
          PairIdToImagePair(static_cast<image_pair_t>(pair_id));
      for (const image_t image_id : {image_id1, image_id2}) {
        if (!images_.count(image_id)) {
          db_.Fail(table + " row " + Str(pair_id) + " (images " +
                   Str(image_id1) + " and " + Str(image_id2) +
                   "): image " + Str(image_id) +
                   " is not in the images table");
        }
      }
      const std::string row = table + " of " + ImageName(image_id1) +
                              " and " + ImageName(image_id2) + ": ";
      const int64_t rows = Int(stmt, 1), cols = Int(stmt, 2);
      if (rows > 0 && cols != 2) {
        db_.Fail(row + Str(cols) + " columns (a match has 2 indices)");
      }
      CheckMatrix(row, rows, cols, Bytes(stmt, 3), sizeof(uint32_t));
      // Each match is a keypoint index in either image.
      const char* data = static_cast<const char*>(sqlite3_column_blob(stmt, 3));
      uint32_t max_index[2] = {0, 0};
      for (int64_t i = 0; i < rows * cols; ++i) {
        uint32_t index;  // the blob need not be aligned
        std::memcpy(&index, data + i * sizeof(index), sizeof(index));
        max_index[i % 2] = std::max(max_index[i % 2], index);
      }
      for (int k = 0; k < 2 && rows > 0; ++k) {
        const image_t image_id = k == 0 ? image_id1 : image_id2;
        const auto keypoints = num_keypoints_.find(image_id);
        const int64_t num =
            keypoints == num_keypoints_.end() ? 0 : keypoints->second;
        if (max_index[k] >= num) {
          db_.Fail(row + "a match refers to keypoint " + Str(max_index[k]) +
                   " of " + ImageName(image_id) + ", which has " + Str(num) +
                   " keypoints");
        }
      }
      if (geometries && (Int(stmt, 4) < 0 || Int(stmt, 4) > kMaxConfig)) {
        db_.Fail(row + "unknown configuration " + Str(Int(stmt, 4)));
      }
      for (size_t i = 0; i < blobs.size(); ++i) {
        const int64_t bytes = Bytes(stmt, 5 + static_cast<int>(i));
        if (bytes != 0 && bytes != blobs[i].second) {
          db_.Fail(row + blobs[i].first + " holds " + Str(bytes) +
                   " bytes, not " + Str(blobs[i].second));
        }
      }
    });
  }

  void CheckRigsAndFrames() {
    std::unordered_set<int64_t> rigs, frames;
    auto check_sensor = [&](const std::string& row, int64_t sensor_id,
                            int64_t sensor_type) {
      if (sensor_type == kCameraSensor && !cameras_.count(sensor_id)) {
        db_.Fail(row + "camera " + Str(sensor_id) +
                 " is not in the cameras table");
      }
    };
    if (tables_.count("rigs")) {
      db_.Query("SELECT rig_id, ref_sensor_id, ref_sensor_type FROM rigs;",
                [&](sqlite3_stmt* stmt) {
                  check_sensor("rig " + Str(Int(stmt, 0)) + ": reference ",
                               Int(stmt, 1), Int(stmt, 2));
                  rigs.insert(Int(stmt, 0));
                });
    }
    if (tables_.count("rig_sensors")) {
      db_.Query("SELECT rig_id, sensor_id, sensor_type FROM rig_sensors;",
                [&](sqlite3_stmt* stmt) {
                  const std::string row =
                      "rig_sensors of rig " + Str(Int(stmt, 0)) + ": ";
                  if (!rigs.count(Int(stmt, 0))) {
                    db_.Fail(row + "the rig is not in the rigs table");
                  }
                  check_sensor(row, Int(stmt, 1), Int(stmt, 2));
                });
    }
    if (tables_.count("frames")) {
      db_.Query("SELECT frame_id, rig_id FROM frames;", [&](sqlite3_stmt* stmt) {
        if (!rigs.count(Int(stmt, 1))) {
          db_.Fail("frame " + Str(Int(stmt, 0)) + " refers to rig " +
                   Str(Int(stmt, 1)) + ", which is not in the rigs table");
        }
        frames.insert(Int(stmt, 0));
      });
    }
    if (tables_.count("frame_data")) {
      db_.Query(
          "SELECT frame_id, data_id, sensor_id, sensor_type FROM frame_data;",
          [&](sqlite3_stmt* stmt) {
            const std::string row = "frame_data of frame " +
                                    Str(Int(stmt, 0)) + ": ";
            if (!frames.count(Int(stmt, 0))) {
              db_.Fail(row + "the frame is not in the frames table");
            }
            check_sensor(row, Int(stmt, 2), Int(stmt, 3));
            if (Int(stmt, 3) == kCameraSensor && !images_.count(Int(stmt, 1))) {
              db_.Fail(row + "image " + Str(Int(stmt, 1)) +
                       " is not in the images table");
            }
          });
    }
  }

  ReadOnlyDatabase db_;
  const int format_version_;
  std::set<std::string> tables_;
  // Camera id -> image width and height.
  std::unordered_map<int64_t, std::pair<int64_t, int64_t>> cameras_;
  std::unordered_map<int64_t, std::string> images_;
  std::unordered_map<int64_t, int64_t> image_cameras_;
  std::unordered_map<std::string, int64_t> image_ids_;
  std::unordered_map<int64_t, int64_t> num_keypoints_;
};

// ": camera C (MODEL) lifts only P% of its image to rays, ..." for the
// cameras of images whose parameters turn fewer than half of a grid of
// pixels into viewing rays (an image circle or field of view far from the
// lens's), or empty.
std::string CamerasLiftingLittle(const ReadOnlyDatabase& db) {
  std::string cameras;
  db.Query(
      "SELECT camera_id, model, width, height, params FROM cameras WHERE "
      "camera_id IN (SELECT camera_id FROM images)",
      [&cameras](sqlite3_stmt* stmt) {
        const CameraModelId model_id =
            static_cast<CameraModelId>(Int(stmt, 1));
        if (!ExistsCameraModelWithId(model_id)) {
          return;
        }
        const size_t num_params = CameraModelNumParams(model_id);
        const double width = Int(stmt, 2);
        const double height = Int(stmt, 3);
        if (num_params == 0 ||
            Bytes(stmt, 4) !=
                static_cast<int64_t>(num_params * sizeof(double))) {
          return;
        }
        std::vector<double> params(num_params);
        std::memcpy(params.data(), sqlite3_column_blob(stmt, 4),
                    num_params * sizeof(double));
        constexpr int kGrid = 20;
        int lifted = 0;
        for (int i = 0; i < kGrid; ++i) {
          for (int j = 0; j < kGrid; ++j) {
            const Eigen::Vector2d pixel((i + 0.5) * width / kGrid,
                                        (j + 0.5) * height / kGrid);
            if (CameraModelCamRayFromImg(model_id, params, pixel)) {
              ++lifted;
            }
          }
        }
        const int percent = 100 * lifted / (kGrid * kGrid);
        if (percent < 50) {
          cameras += (cameras.empty() ? ": camera " : ", camera ") +
                     Str(Int(stmt, 0)) + " (" +
                     CameraModelIdToName(model_id) + ") lifts only " +
                     Str(percent) + "% of its image to rays";
        }
      });
  return cameras;
}

}  // namespace

bool HoldsDatabase(const std::filesystem::path& path) {
  std::error_code error;
  return std::filesystem::exists(path, error) &&
         std::filesystem::file_size(path, error) > 0 && !error;
}

std::string NoVerifiedPairError(const std::filesystem::path& path,
                                const int min_num_inliers) {
  if (!HoldsDatabase(path)) {
    return "";
  }
  const ReadOnlyDatabase db(path);
  const auto count = [&db](const std::string& sql) {
    int64_t n = 0;
    db.Query(sql, [&n](sqlite3_stmt* stmt) { n = Int(stmt, 0); });
    return n;
  };
  const std::string name = "database " + path.string() + ": ";
  if (count("SELECT count(*) FROM two_view_geometries WHERE rows > 0 AND "
            "config >= 2") > 0) {
    return "";
  }
  const int64_t num_images = count("SELECT count(*) FROM images");
  if (num_images < 2) {
    return name + "holds " + Str(num_images) +
           " image(s): there is no image pair to match";
  }
  const int64_t num_pairs = count(
      "SELECT count(*) FROM (SELECT pair_id FROM matches UNION "
      "SELECT pair_id FROM two_view_geometries)");
  if (num_pairs == 0) {
    int64_t num_priors = 0;
    if (count("SELECT count(*) FROM sqlite_master WHERE type = 'table' AND "
              "name = 'pose_priors'") > 0) {
      num_priors = count("SELECT count(*) FROM pose_priors WHERE position "
                         "IS NOT NULL");
    }
    return name + "no image pair was matched: the pairing selected none of "
                  "the " + Str(num_images) + " images' pairs (spatial_matcher "
                  "pairs images with position priors, here " +
           Str(num_priors) + "; transitive_matcher extends matched pairs)";
  }
  const std::string threshold = Str(std::max(min_num_inliers, 1));
  const int64_t num_enough =
      count("SELECT count(*) FROM matches WHERE rows >= " + threshold);
  const int64_t most = count("SELECT coalesce(max(rows), 0) FROM matches");
  std::string why;
  if (num_enough > 0) {
    const std::string cameras = CamerasLiftingLittle(db);
    why = Str(num_enough) + (num_enough == 1 ? " has" : " have") +
          " at least " + threshold +
          " raw matches, yet no two-view geometry fits any" +
          (cameras.empty()
               ? ": the images may show different scenes, or a camera's "
                 "model or parameters are wrong (a wrong camera makes every "
                 "pair fail)."
               : ". Check the cameras' models and parameters" + cameras +
                     ".");
  } else {
    why = "none has the " + threshold +
          " raw matches a two-view geometry needs" +
          (most > 0 ? " (the most: " + Str(most) + ")" : "") +
          ": the images may not overlap or have too few features.";
  }
  return name + "no image pair passed geometric verification: of " +
         Str(num_pairs) + " pairs matched, " + why +
         " A mapper has nothing to start from; the matches are kept.";
}

std::string MatchOfMissingKeypointError(const uint32_t image_id1,
                                        const uint32_t image_id2,
                                        const uint32_t image_id,
                                        const uint32_t point2D_idx,
                                        const size_t num_keypoints) {
  return "the verified matches of images " + Str(image_id1) + " and " +
         Str(image_id2) + " refer to keypoint " + Str(point2D_idx) +
         " of image " + Str(image_id) + ", which has " + Str(num_keypoints) +
         " keypoints: the database's matches do not belong to its keypoints "
         "(match the images again)";
}

void CheckDatabaseFile(const std::filesystem::path& path,
                       const int format_version) {
  if (!HoldsDatabase(path)) {
    return;
  }
  DatabaseChecker(path, format_version).Run();
}

std::shared_ptr<Database> OpenDatabase(
    const std::vector<Database::Factory>& factories,
    const std::filesystem::path& path) {
  std::string reason = "no database factory registered";
  for (auto it = factories.rbegin(); it != factories.rend(); ++it) {
    try {
      return (*it)(path);
    } catch (const std::exception& e) {
      reason = e.what();
      if (std::next(it) != factories.rend()) {
        LOG(WARNING) << "Failed to open database with registered factory, "
                        "because: "
                     << reason << ". Trying next registered factory.";
      }
    }
  }
  if (reason.rfind("database ", 0) != 0) {
    reason = "database " + path.string() + ": " + reason;
  }
  throw std::runtime_error(reason);
}

}  // namespace colmap
