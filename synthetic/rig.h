// Multi-lens 360° cameras for the renderer: a rig of lenses (sensors) with
// their sensor_from_rig poses, moved along a path of frames, rendered lens by
// lens, plus what the camera itself would give a user: the raw dual-fisheye
// frame (both image circles side by side) and the panorama a stitcher makes
// of it.
//
// Dataset layout (DIR is written as DIR.tmp, then renamed; see model_io.h):
//   DIR/images/SENSOR/frameNNN.EXT    one image per lens and frame
//   DIR/masks/SENSOR/frameNNN.EXT.png the lens's image circle (255 inside; with
//                                     sensor effects the smaller of it and theirs),
//                                     COLMAP's --ImageReader.mask_path layout
//   DIR/depth/SENSOR/frameNNN.EXT.depth.bin
//   DIR/sparse_gt/                    cameras (one per lens), images, points3D,
//                                     rigs.txt and frames.txt (COLMAP 4 text)
//   DIR/rig_config.json               the true rig for `colmap rig_configurator`
//   DIR/circles.txt                   'SENSOR CX CY R' per lens (pixels)
//   DIR/raw/frameNNN.EXT              with --raw: [lens 0 | lens 1] side by side
//   DIR/stitched/{images,depth,sparse_gt}/  with --stitched: one
//                                     EQUIRECTANGULAR panorama per frame at the
//                                     mean of the lens centres, oriented as the
//                                     rig (see StitchSpec in render.h)
#ifndef SPHERA_SYNTHETIC_RIG_H_
#define SPHERA_SYNTHETIC_RIG_H_

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "synthetic/model_io.h"
#include "synthetic/render.h"
#include "synthetic/scene.h"

namespace sphera {
namespace synthetic {

struct RigSensor {
  std::string name;  // image folder of the lens, e.g. "lens0"
  std::string model_name;
  int width = 0;
  int height = 0;
  std::vector<double> params;
  // x_sensor = rotation * x_rig + translation. The first sensor is the
  // reference: identity.
  Eigen::Quaterniond sensor_from_rig_rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d sensor_from_rig_translation = Eigen::Vector3d::Zero();
  // Half the lens's field of view: the image circle is where rays at this
  // angle from the axis land (0: no image circle, the whole image).
  double max_angle_deg = 0;
};

// dual_fisheye: two back-to-back 200° lenses (DOUBLE_SPHERE and
//   UNIFIED_OMNI with slightly different intrinsics, as real lenses are),
//   3 cm apart along the rig's z axis, image circles of radius 0.47 * size.
// ring8: 8 outward-looking 195° EUCM lenses on a horizontal ring of radius
//   6 cm (a Vuze-like camera), every other lens 1 cm higher.
// `lens_size`: pixels of a square lens image (0: 1024 for dual_fisheye, 640
// for ring8). Empty string on success.
std::string MakeRigPreset(const std::string& preset, int lens_size,
                          std::vector<RigSensor>* sensors);

// Reads a rig of sensors: one line per lens
//   NAME MODEL WIDTH HEIGHT PARAMS... | QW QX QY QZ TX TY TZ [MAX_ANGLE_DEG]
// (sensor_from_rig; the first line is the reference and must be identity).
std::string ReadRigSensors(const std::string& path, std::vector<RigSensor>* sensors);

// The image circle (cx, cy, r) of a lens: centred on the principal point,
// through the projection of a ray at max_angle_deg (mean radius over 8
// azimuths). Empty string on success.
std::string ImageCircle(const RigSensor& sensor, Eigen::Vector3d* circle);

struct RigFrame {
  Eigen::Quaterniond rig_from_world_rotation;
  Eigen::Vector3d rig_from_world_translation;
};

// `num_frames` rig poses on a closed loop through the room (an ellipse of
// 1.0 x 0.8 m half-axes around the room's centre, 1.5 m above the floor with
// +-5 cm of height), heading along the loop with random yaw, pitch and roll
// of a few degrees, as a camera carried on a pole.
std::vector<RigFrame> MakeFramePath(int num_frames, uint64_t seed);

struct RigDatasetOptions {
  DatasetOptions dataset;
  std::string image_extension = ".jpg";
  bool raw = false;        // write the side-by-side raw frames (two lenses)
  bool stitched = false;   // write the stitched panoramas
  int stitched_width = 2048;
  double stitch_band_deg = 10;
  double stitch_distance_m = 0;
};

// Renders every lens of every frame and writes the dataset described above.
// Empty string on success, else a message naming the lens or frame.
std::string WriteRigDataset(const std::string& output_dir, const Scene& scene,
                            const std::vector<RigSensor>& sensors,
                            const std::vector<RigFrame>& frames,
                            const RigDatasetOptions& options, std::ostream* log);

}  // namespace synthetic
}  // namespace sphera

#endif  // SPHERA_SYNTHETIC_RIG_H_
