// Library code of `colmap sphere_undistorter` (COLMAP 4.x): turns every
// registered image of a reconstruction (panoramas, fisheye and catadioptric
// images, perspective images) into perspective PINHOLE views and writes a
// COLMAP dense workspace (images/, sparse/, stereo/) that patch_match_stereo,
// OpenMVS's COLMAP importer and Gaussian-splatting trainers read.
//
// Sphere models (EQUIRECTANGULAR, UNIFIED_OMNI, EUCM, DOUBLE_SPHERE) and
// COLMAP's wide-angle models (OPENCV_FISHEYE, FOV, SIMPLE_RADIAL_FISHEYE,
// RADIAL_FISHEYE, THIN_PRISM_FISHEYE, and every other model that is not one of
// the perspective models listed in IsCubeMappedModel) become cube-map faces:
// each face is a virtual PINHOLE camera at the image's centre, rotated by the
// face rotation (face_from_world = face_from_cam * cam_from_world). Faces with
// more than `max_invalid_ratio` of pixels outside the source image are
// skipped. COLMAP's perspective models are undistorted as image_undistorter
// does and stay one view.
//
// In the written model every view is an image with a trivial frame (frame id =
// image id) of a trivial rig (rig id = camera id); views of identical
// intrinsics share one camera.
#pragma once

#include "colmap/geometry/rigid3.h"
#include "colmap/scene/camera.h"
#include "colmap_ext/scene/camera_params_error.h"
#include "colmap/scene/reconstruction.h"

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace colmap {

enum class CubeFace { kFront = 0, kRight, kBack, kLeft, kUp, kDown };

// Layout of the written workspace; only COLMAP's is supported.
enum class SphereOutputType { kColmap };

// File format of the face images.
enum class SphereImageFormat { kJpg, kPng };

// The enumerations of SphereUndistorterOptions, parsed once from their text.
struct ParsedSphereUndistorterOptions {
  std::vector<CubeFace> faces;
  SphereOutputType output_type = SphereOutputType::kColmap;
  SphereImageFormat image_format = SphereImageFormat::kJpg;
};

struct SphereUndistorterOptions {
  // The largest face side accepted (a face of 16384² RGB pixels is 768 MiB).
  static constexpr int kMaxFaceSize = 16384;
  // Side of the square cube faces in pixels; 0 picks it per source camera:
  // w/4 * tan(fov/2) for EQUIRECTANGULAR (w/4 at 90 degrees), otherwise the
  // source's resolution at its centre (focal length 1 / radians per pixel).
  int face_size = 0;
  // Field of view of a face, in degrees; must be in (0, 180).
  double fov_deg = 90;
  // Extra field of view added to every face (faces overlap by this much at
  // each edge); fov_deg + overlap_deg must stay below 180.
  double overlap_deg = 0;
  // Comma-separated subset of front,right,back,left,up,down (camera frame:
  // front = +z, right = +x, up = -y), e.g. without "down" under a tripod.
  std::string faces = "front,right,back,left,up,down";
  // Only COLMAP's workspace layout is written ("COLMAP" or "colmap").
  std::string output_type = "COLMAP";
  // true: write only images/ and sparse/0/ (PINHOLE cameras), the layout
  // Gaussian-splatting trainers read; image folders are flattened
  // ("a/b.jpg" -> "a_b_front.jpg") because such trainers look images up by
  // base name.
  bool splatting = false;
  // A face is dropped when more than this fraction of its pixels sees no
  // source pixel (fisheye images below 180 degrees). In [0, 1].
  double max_invalid_ratio = 0.9;
  // Number of source images per reference image in stereo/patch-match.cfg.
  int num_patch_match_src_images = 20;
  // Format of the face images: "jpg" or "png". Perspective images keep their
  // name and format.
  std::string image_format = "jpg";
  // JPEG quality of the face images, in [1, 100].
  int jpeg_quality = 95;
  // Masks of the source images (ImageReader.mask_path's layout: MASK_PATH/
  // NAME.png, 0 = ignore, e.g. a fisheye lens's image circle or a user's
  // mask). When set, every view gets OUTPUT/masks/VIEW_NAME.png: the source
  // mask carried into the view (nearest pixel), 0 where the view sees no
  // source pixel. An image without a mask file counts as unmasked.
  std::string mask_path;
  // true: the lenses of a rig frame share its directions instead of each
  // writing every face it sees. A face pixel of a lens is kept only where
  // its ray is nearer that lens's optical axis (+z) than the axis of any
  // other registered image of the same frame, so each direction around a
  // frame comes from one lens (the one that sees it nearest its centre) and
  // the overlap of the lenses is not written twice; faces left with more
  // than max_invalid_ratio of such pixels are dropped. Views stay exact
  // pinhole views of one lens each (no stitching, no parallax). Images
  // alone in their frame are unaffected.
  bool per_frame = false;

  // Empty when valid; otherwise a message naming the offending option.
  std::string Check() const;

  // Check() that also fills `parsed` (left unspecified on failure).
  std::string Parse(ParsedSphereUndistorterOptions* parsed) const;
};

// "front", "right", ...
const char* CubeFaceName(CubeFace face);

// Parses a comma-separated face list. Empty message on success; otherwise a
// message naming the `faces` option and the bad entry.
std::string ParseCubeFaces(const std::string& list,
                           std::vector<CubeFace>* faces);

// Parse the `output_type` / `image_format` option. Empty message on success;
// otherwise a message naming the option and the bad value.
std::string ParseSphereOutputType(const std::string& text,
                                  SphereOutputType* output_type);
std::string ParseSphereImageFormat(const std::string& text,
                                   SphereImageFormat* image_format);

// File extension without the dot: "jpg" or "png".
const char* SphereImageFormatExtension(SphereImageFormat image_format);

// Rotation taking camera-frame rays to face-frame rays (x right, y down,
// z forward in the face image).
Eigen::Matrix3d FaceFromCamRotation(CubeFace face);

// view_from_world = view_from_cam * cam_from_world: a view turned from the
// camera about its centre (a cube face, a lens's own direction).
Rigid3d ViewFromWorld(const Eigen::Matrix3d& view_from_cam,
                      const Rigid3d& cam_from_world);

// PINHOLE face camera: f = size/2 / tan(fov/2), c = size/2.
Camera MakeFaceCamera(int face_size, double fov_deg);

// Face size that `face_size = 0` picks for this source camera.
int AutoFaceSize(const Camera& source, double fov_deg);

// True for the models that become cube faces (sphere and wide-angle models).
bool IsCubeMappedModel(CameraModelId model_id);

// The source pixel (COLMAP convention: pixel centres at +0.5) seen by
// `view_pixel` of a view camera rotated by `cam_from_view` at the source
// camera's centre. False when the view ray is not visible in the source
// image, or when it is nearer one of `other_lens_axes` (unit vectors in the
// source camera's frame) than the source's own optical axis (+z).
bool ViewPixelToSourcePixel(
    const Camera& source,
    const Camera& view,
    const Eigen::Matrix3d& cam_from_view,
    const Eigen::Vector2d& view_pixel,
    Eigen::Vector2d* source_pixel,
    const std::vector<Eigen::Vector3d>& other_lens_axes = {});

// The optical axes (+z) of the other registered images of `image`'s frame,
// in `image`'s camera frame (empty for an image alone in its frame).
std::vector<Eigen::Vector3d> OtherLensAxes(const Reconstruction& reconstruction,
                                           const Image& image);

// True when `ray` (source camera frame) is at least as near the source's
// optical axis (+z) as every one of `other_lens_axes`.
bool NearestLens(const std::vector<Eigen::Vector3d>& other_lens_axes,
                 const Eigen::Vector3d& ray);

// cv::remap maps (OpenCV convention: pixel centres at integers) from a view
// to the source image; pixels without a source hold kInvalidMapValue.
struct RemapMaps {
  cv::Mat map_x;  // CV_32F, view height x view width
  cv::Mat map_y;
  double invalid_ratio = 0;
};
constexpr float kInvalidMapValue = -1e6f;

RemapMaps BuildRemapMaps(
    const Camera& source,
    const Camera& view,
    const Eigen::Matrix3d& cam_from_view,
    const std::vector<Eigen::Vector3d>& other_lens_axes = {});

// Bilinear resampling of `source_image` (the image of `source`) through the
// maps; the equirectangular seam wraps around, pixels without a source are
// black.
cv::Mat RemapImage(const cv::Mat& source_image,
                   const Camera& source,
                   const RemapMaps& maps);

struct SphereExportSummary {
  size_t num_input_images = 0;
  size_t num_views = 0;
  size_t num_points3D = 0;
  size_t num_observations = 0;
  size_t num_bytes = 0;
  double seconds = 0;
};

// Writes the workspace for the registered images of `reconstruction` (images
// read from `image_path`) into `output_path`: images/, sparse/ (or sparse/0/
// with options.splatting) and stereo/. The output is assembled in a sibling
// OUTPUT.tmp-XXXXXX folder and moved into place only when complete. Throws
// std::invalid_argument with a message (naming the option or image) on bad
// options, a missing or unreadable image, an image whose size differs from
// its camera, or an output that already holds a workspace; nothing is left
// behind then.
SphereExportSummary ExportPerspectiveWorkspace(
    const Reconstruction& reconstruction,
    const std::string& image_path,
    const std::string& output_path,
    const SphereUndistorterOptions& options);

// "image NAME not found in IMAGE_PATH (and N more missing images)" for the
// first of `image_ids` whose file is not under `image_path`, or "image NAME:
// FILE <damage>" for a JPEG or PNG file that is not a whole image
// (ImageBytesError); empty when every file is there and whole. Used by both
// undistorters before they write anything.
std::string MissingImageFiles(const Reconstruction& reconstruction,
                              const std::vector<image_t>& image_ids,
                              const std::string& image_path);

// Empty, or why image_undistorter would write a workspace without a view:
// the reconstruction at `input_path` has no registered image, none of the
// images of `image_list_path` (when given; `image_ids` are those found) is
// in it, or an image file of the views is missing (MissingImageFiles).
std::string ImageUndistorterInputError(
    const Reconstruction& reconstruction,
    const std::vector<image_t>& image_ids,
    const std::filesystem::path& input_path,
    const std::filesystem::path& image_list_path,
    const std::string& image_path);

}  // namespace colmap
