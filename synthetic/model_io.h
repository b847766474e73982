// Camera layouts, rig files and the ground-truth dataset written to disk in
// COLMAP's text format.
//
// Dataset layout (DIR is written as DIR.tmp, then renamed):
//   DIR/images/NAME                    rendered 8-bit JPEG (quality 95 unless the sensor
//                                      effects set one) or PNG
//   DIR/depth/NAME.depth.bin           range map, see WriteDepthMap (render.h)
//   DIR/sparse_gt/cameras.txt          CAMERA_ID MODEL WIDTH HEIGHT PARAMS[] (model names)
//   DIR/sparse_gt/images.txt           IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, then
//                                      POINTS2D[] as (X, Y, POINT3D_ID) (empty without points)
//   DIR/sparse_gt/points3D.txt         POINT3D_ID X Y Z R G B ERROR TRACK[] (IMAGE_ID, POINT2D_IDX)
//   DIR/rig.txt                        the cameras in rig-file format (reproducible input)
//   DIR/masks/NAME.png                 for cameras with an image circle (their own or the
//                                      sensor effects'), or every camera with write_masks:
//                                      255 where the pixel sees the scene (ValidPixelMask)
//   DIR/sparse_gt/{rigs,frames}.txt    for a rig (DatasetOptions::rig), COLMAP 4 text
// Poses are cam_from_world (COLMAP). Pixels: upper-left image corner is (0, 0).
//
// Rig file: one camera per line, '#' starts a comment:
//   NAME MODEL WIDTH HEIGHT PARAMS... | QW QX QY QZ TX TY TZ
#ifndef SPHERA_SYNTHETIC_MODEL_IO_H_
#define SPHERA_SYNTHETIC_MODEL_IO_H_

#include <cstdint>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "synthetic/file_formats.h"
#include "synthetic/render.h"
#include "synthetic/scene.h"
#include "synthetic/sensor_effects.h"

namespace sphera {
namespace synthetic {

// Default parameters for a model at a given image size: focal lengths so
// that a perspective camera sees 90 degrees horizontally and a fisheye model
// maps 95 degrees off-axis (a 190 degree field) to 0.48 * min(width, height)
// from the image centre. Empty `error` on success.
std::vector<double> DefaultParams(const std::string& model_name, int width, int height,
                                  std::string* error);

// Parses "1,2,3" (commas and/or blanks). False on a malformed number.
bool ParseParamList(const std::string& text, std::vector<double>* values);

struct LayoutOptions {
  // room9: the paper's 9 cameras on a 3 x 3 grid (1 m spacing, 1.5 m above
  //        the floor, small random rotations).
  // ring:  N cameras on a 0.6 m circle looking outwards at the walls, with
  //        alternating small height offsets (for perspective/stock COLMAP).
  // grid:  N cameras on a square-ish grid over [-1.2, 1.2]^2, random heading.
  std::string layout = "room9";
  int num_cameras = 0;  // 0: the layout's default (room9: 9, ring: 16, grid: 9)
  std::string model_name;  // empty: the layout's default model
  int width = 0;           // 0: the layout's default size
  int height = 0;
  std::vector<double> params;  // empty: DefaultParams
  uint64_t seed = 0;
  std::string image_extension = ".jpg";
};

// Empty string on success, else a message.
std::string MakeLayout(const LayoutOptions& options, std::vector<VirtualCamera>* cameras);

// Calls `parse(line, where)` for every line of the text file `path` that
// holds data ('#' starts a comment); `where` is "PATH:LINE: ". Returns the
// first non-empty message of `parse`, "cannot read PATH", or "".
std::string ForEachDataLine(
    const std::string& path,
    const std::function<std::string(const std::string& line, const std::string& where)>& parse);

// Reads a rig file. Names without .jpg/.jpeg/.png get `default_extension`.
// Empty string on success, else a message naming the line and camera.
std::string ReadRigFile(const std::string& path, const std::string& default_extension,
                        std::vector<VirtualCamera>* cameras);

// Checks every camera (model, parameters, size, pose), unique names and that
// every centre lies in the free space of the scene.
std::string CheckCameras(const Scene& scene, const std::vector<VirtualCamera>& cameras);

struct PointObservation {
  int image_index = 0;  // index into the camera list
  Eigen::Vector2d pixel;
};

struct GroundTruthPoint {
  Eigen::Vector3d xyz;
  Eigen::Vector3i rgb;
  std::vector<PointObservation> observations;
};

// Up to `num_points` random surface points seen unoccluded by at least two
// cameras (inside their image circles), with their exact projections.
std::vector<GroundTruthPoint> SamplePoints(const Scene& scene,
                                           const std::vector<VirtualCamera>& cameras,
                                           int num_points, uint64_t seed);

// The rig of a dataset: sensors (index 0 is the reference), frames, and for
// every camera of the dataset its sensor and frame.
struct RigGroundTruth {
  std::vector<std::string> sensor_names;
  std::vector<Eigen::Quaterniond> sensor_from_rig_rotation;
  std::vector<Eigen::Vector3d> sensor_from_rig_translation;
  std::vector<Eigen::Quaterniond> rig_from_world_rotation;  // per frame
  std::vector<Eigen::Vector3d> rig_from_world_translation;
  std::vector<int> image_sensor;  // per camera
  std::vector<int> image_frame;
};

struct DatasetOptions {
  RenderOptions render;
  // Applied to every image after the lens projection; they change pixels
  // only, never the ground truth. In a rig each sensor is one lens.
  SensorEffects effects;
  // Write DIR/masks/NAME.png for every camera, not only those with a circle.
  bool write_masks = false;
  int num_points = 0;
  uint64_t points_seed = 0;
  // Set for a rig: one camera per sensor, rigs.txt and frames.txt.
  const RigGroundTruth* rig = nullptr;
  // Writes further outputs into the staging directory before it is renamed
  // into place; returns an error message or "".
  std::function<std::string(const std::string& staging_dir, std::ostream* log)> extra;
};


// Renders every camera and writes the dataset into `output_dir` atomically
// (via output_dir + ".tmp"). Refuses an existing non-empty `output_dir`.
// Progress goes to `log` if not null. Empty string on success.
std::string WriteDataset(const std::string& output_dir, const Scene& scene,
                         const std::vector<VirtualCamera>& cameras,
                         const DatasetOptions& options, std::ostream* log);

}  // namespace synthetic
}  // namespace sphera

#endif  // SPHERA_SYNTHETIC_MODEL_IO_H_
