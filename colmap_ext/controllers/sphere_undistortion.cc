#include "colmap_ext/controllers/sphere_undistortion.h"

#include "camera_models/registry.h"
#include "colmap/image/undistortion.h"
#include "colmap/scene/image.h"
#include "colmap/scene/point2d.h"
#include "colmap/scene/point3d.h"
#include "colmap/scene/track.h"
#include "colmap/sensor/models.h"
#include "colmap/util/logging.h"
#include "colmap/util/string.h"
#include "colmap/util/timer.h"
#include "colmap_ext/image/image_file_structure.h"
#include "colmap_ext/util/file_output.h"
#include "synthetic/file_formats.h"
#include "colmap/util/types.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <unordered_map>
#include <utility>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace colmap {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;
constexpr CubeFace kAllFaces[] = {CubeFace::kFront,
                                  CubeFace::kRight,
                                  CubeFace::kBack,
                                  CubeFace::kLeft,
                                  CubeFace::kUp,
                                  CubeFace::kDown};
// Border added around the source image before cv::remap so that bilinear
// sampling at the image edge (and across the equirectangular seam) has
// neighbours.
constexpr int kRemapPadding = 2;
// Rays closer than this (relative to their length) to the image plane of a
// plane-based model (COLMAP's own models) are "not visible": their
// projection is unbounded.
constexpr double kMinPlaneDepth = 1e-12;

std::string Trim(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t");
  if (begin == std::string::npos) {
    return "";
  }
  const size_t end = text.find_last_not_of(" \t");
  return text.substr(begin, end - begin + 1);
}

bool InsideImage(const Eigen::Vector2d& pixel,
                 const size_t width,
                 const size_t height) {
  return pixel.x() >= 0 && pixel.y() >= 0 &&
         pixel.x() < static_cast<double>(width) &&
         pixel.y() < static_cast<double>(height);
}

// Unit ray of a pixel over the model's whole field of view (rays behind the
// image plane included for the sphere models).
std::optional<Eigen::Vector3d> PixelRay(const Camera& camera,
                                        const Eigen::Vector2d& pixel) {
  const std::optional<Eigen::Vector3d> ray = camera.CamRayFromImg(pixel);
  if (!ray.has_value() || !ray->allFinite()) {
    return std::nullopt;
  }
  const double norm = ray->norm();
  if (!(norm > 0)) {
    return std::nullopt;
  }
  return Eigen::Vector3d(*ray / norm);
}

// Pixel of a ray (any length): for the sphere models (IsSpherical in 4.x:
// EQUIRECTANGULAR, EUCM, UNIFIED_OMNI, DOUBLE_SPHERE) nullopt outside the
// model's field of view, which may reach behind the image plane; for the
// plane-based models nullopt at or behind the image plane.
std::optional<Eigen::Vector2d> RayPixel(const Camera& camera,
                                        const Eigen::Vector3d& ray_in_cam) {
  if (!ray_in_cam.allFinite()) {
    return std::nullopt;
  }
  const double norm = ray_in_cam.norm();
  if (!(norm > 0)) {
    return std::nullopt;
  }
  const Eigen::Vector3d unit_ray = ray_in_cam / norm;
  if (!camera.IsSpherical() && unit_ray.z() <= kMinPlaneDepth) {
    return std::nullopt;
  }
  const std::optional<Eigen::Vector2d> pixel =
      camera.ImgFromCam(unit_ray, /*check_cheirality=*/true);
  if (!pixel.has_value() || !pixel->allFinite()) {
    return std::nullopt;
  }
  return pixel;
}

// One perspective view written for a source image.
struct View {
  std::string name;       // name in the workspace
  std::string face_name;  // "front", ..., or "undistorted"
  Camera camera;          // PINHOLE
  Eigen::Matrix3d view_from_cam = Eigen::Matrix3d::Identity();
  int cache_key = 0;  // face index, or -1 for an undistorted image
};

std::string ViewName(const std::string& image_name,
                     const std::string& suffix,
                     const SphereUndistorterOptions& options,
                     const ParsedSphereUndistorterOptions& parsed) {
  std::string name = image_name;
  if (!suffix.empty()) {
    const size_t slash = name.find_last_of('/');
    const size_t dot = name.find_last_of('.');
    if (dot != std::string::npos &&
        (slash == std::string::npos || dot > slash)) {
      name = name.substr(0, dot);
    }
    name += "_" + suffix + "." +
            SphereImageFormatExtension(parsed.image_format);
  }
  if (options.splatting) {
    for (char& c : name) {
      if (c == '/' || c == '\\') {
        c = '_';
      }
    }
  }
  return name;
}

// The views of one source image (before the invalid-ratio filter).
std::vector<View> PlanViews(const Image& image,
                            const Camera& camera,
                            const SphereUndistorterOptions& options,
                            const ParsedSphereUndistorterOptions& parsed) {
  std::vector<View> views;
  if (IsCubeMappedModel(camera.model_id)) {
    const double fov = options.fov_deg + options.overlap_deg;
    const int size = options.face_size > 0 ? options.face_size
                                           : AutoFaceSize(camera, fov);
    for (const CubeFace face : parsed.faces) {
      View view;
      view.face_name = CubeFaceName(face);
      view.name = ViewName(image.Name(), view.face_name, options, parsed);
      view.camera = MakeFaceCamera(size, fov);
      view.view_from_cam = FaceFromCamRotation(face);
      view.cache_key = static_cast<int>(face);
      views.push_back(std::move(view));
    }
  } else {
    View view;
    view.face_name = "undistorted";
    view.name = ViewName(image.Name(), "", options, parsed);
    view.camera = UndistortCamera(UndistortCameraOptions(), camera);
    view.cache_key = -1;
    views.push_back(std::move(view));
  }
  return views;
}

// Empty when `output` can receive a workspace: it does not exist, or is a
// folder whose images/, sparse/ and stereo/ are absent or empty.
std::string OutputConflict(const fs::path& output) {
  std::error_code error;
  if (!fs::exists(output, error)) {
    return "";
  }
  if (!fs::is_directory(output, error)) {
    return "output_path: " + output.string() + " exists and is not a folder";
  }
  for (const char* entry : {"images", "sparse", "stereo"}) {
    const fs::path sub = output / entry;
    if (!fs::exists(sub, error)) {
      continue;
    }
    if (!fs::is_directory(sub, error) || !fs::is_empty(sub, error)) {
      return "output_path: " + output.string() +
             " already holds a workspace (" + entry +
             "/ is not empty); choose an empty or new folder";
    }
  }
  return "";
}

size_t FolderBytes(const fs::path& folder) {
  size_t bytes = 0;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (entry.is_regular_file()) {
      bytes += entry.file_size();
    }
  }
  return bytes;
}

void CreateFolders(const fs::path& root, const std::string& name) {
  const fs::path parent = (root / name).parent_path();
  fs::create_directories(parent);
}

void WriteImage(const std::string& path,
                const cv::Mat& image,
                const SphereUndistorterOptions& options) {
  std::vector<int> params;
  cv::Mat output = image;
  if (sphera::IsJpegFileName(path)) {
    params = sphera::ImageWriteParams(path, options.jpeg_quality);
    if (image.channels() == 4) {
      cv::cvtColor(image, output, cv::COLOR_BGRA2BGR);
    }
  }
  bool ok = false;
  try {
    ok = cv::imwrite(path, output, params);
  } catch (const cv::Exception& error) {
    throw std::runtime_error("cannot write " + path + ": " + error.what());
  }
  if (!ok) {
    throw std::runtime_error("cannot write " + path);
  }
}

}  // namespace

std::string SphereUndistorterOptions::Parse(
    ParsedSphereUndistorterOptions* parsed) const {
  std::ostringstream message;
  if (face_size < 0 || face_size > kMaxFaceSize) {
    message << "face_size must be in [1, " << kMaxFaceSize
            << "] pixels, or 0 to pick it automatically; got " << face_size;
  } else if (!(fov_deg > 0 && fov_deg < 180)) {
    message << "fov_deg must be in (0, 180) degrees, got " << fov_deg;
  } else if (!(overlap_deg >= 0)) {
    message << "overlap_deg must be >= 0, got " << overlap_deg;
  } else if (!(fov_deg + overlap_deg < 180)) {
    message << "fov_deg + overlap_deg must be below 180 degrees, got "
            << fov_deg << " + " << overlap_deg;
  } else if (std::string type_error =
                 ParseSphereOutputType(output_type, &parsed->output_type);
             !type_error.empty()) {
    return type_error;
  } else if (!(max_invalid_ratio >= 0 && max_invalid_ratio <= 1)) {
    message << "max_invalid_ratio must be in [0, 1], got "
            << max_invalid_ratio;
  } else if (num_patch_match_src_images <= 0) {
    message << "num_patch_match_src_images must be positive, got "
            << num_patch_match_src_images;
  } else if (std::string format_error =
                 ParseSphereImageFormat(image_format, &parsed->image_format);
             !format_error.empty()) {
    return format_error;
  } else if (jpeg_quality < 1 || jpeg_quality > 100) {
    message << "jpeg_quality must be in [1, 100], got " << jpeg_quality;
  } else {
    return ParseCubeFaces(faces, &parsed->faces);
  }
  return message.str();
}

std::string SphereUndistorterOptions::Check() const {
  ParsedSphereUndistorterOptions parsed;
  return Parse(&parsed);
}

const char* CubeFaceName(const CubeFace face) {
  switch (face) {
    case CubeFace::kFront:
      return "front";
    case CubeFace::kRight:
      return "right";
    case CubeFace::kBack:
      return "back";
    case CubeFace::kLeft:
      return "left";
    case CubeFace::kUp:
      return "up";
    case CubeFace::kDown:
      return "down";
  }
  return "?";
}

std::string ParseCubeFaces(const std::string& list,
                           std::vector<CubeFace>* faces) {
  faces->clear();
  std::stringstream stream(list);
  std::string item;
  std::set<CubeFace> seen;
  while (std::getline(stream, item, ',')) {
    item = Trim(item);
    StringToLower(&item);
    if (item.empty()) {
      continue;
    }
    bool found = false;
    for (const CubeFace face : kAllFaces) {
      if (item == CubeFaceName(face)) {
        found = true;
        if (!seen.insert(face).second) {
          return "faces: '" + item + "' is listed twice";
        }
        faces->push_back(face);
      }
    }
    if (!found) {
      return "faces: unknown face '" + item +
             "' (expected a comma-separated subset of "
             "front,right,back,left,up,down)";
    }
  }
  if (faces->empty()) {
    return "faces: no face given (expected a comma-separated subset of "
           "front,right,back,left,up,down)";
  }
  return "";
}

std::string ParseSphereOutputType(const std::string& text,
                                  SphereOutputType* output_type) {
  // In any letter case, as COLMAP's enum options.
  std::string lower = text;
  StringToLower(&lower);
  if (lower == "colmap") {
    *output_type = SphereOutputType::kColmap;
    return "";
  }
  return "output_type: only COLMAP is supported, got '" + text + "'";
}

std::string ParseSphereImageFormat(const std::string& text,
                                   SphereImageFormat* image_format) {
  std::string lower = text;
  StringToLower(&lower);
  if (lower == "jpg" || lower == "jpeg") {
    *image_format = SphereImageFormat::kJpg;
    return "";
  }
  if (lower == "png") {
    *image_format = SphereImageFormat::kPng;
    return "";
  }
  return "image_format must be jpg or png, got '" + text + "'";
}

const char* SphereImageFormatExtension(const SphereImageFormat image_format) {
  switch (image_format) {
    case SphereImageFormat::kJpg:
      return "jpg";
    case SphereImageFormat::kPng:
      return "png";
  }
  return "jpg";
}

Eigen::Matrix3d FaceFromCamRotation(const CubeFace face) {
  // Rows: the face's x (image right), y (image down) and z (viewing
  // direction) axes in the camera frame; x = y cross z (right-handed).
  Eigen::Vector3d y(0, 1, 0);
  Eigen::Vector3d z(0, 0, 1);
  switch (face) {
    case CubeFace::kFront:
      break;
    case CubeFace::kRight:
      z = Eigen::Vector3d(1, 0, 0);
      break;
    case CubeFace::kBack:
      z = Eigen::Vector3d(0, 0, -1);
      break;
    case CubeFace::kLeft:
      z = Eigen::Vector3d(-1, 0, 0);
      break;
    case CubeFace::kUp:  // -y is up; the image bottom points to the front.
      z = Eigen::Vector3d(0, -1, 0);
      y = Eigen::Vector3d(0, 0, 1);
      break;
    case CubeFace::kDown:  // the image top points to the front.
      z = Eigen::Vector3d(0, 1, 0);
      y = Eigen::Vector3d(0, 0, -1);
      break;
  }
  Eigen::Matrix3d rotation;
  rotation.row(0) = y.cross(z);
  rotation.row(1) = y;
  rotation.row(2) = z;
  return rotation;
}

Rigid3d ViewFromWorld(const Eigen::Matrix3d& view_from_cam,
                      const Rigid3d& cam_from_world) {
  return Rigid3d(Eigen::Quaterniond(view_from_cam), Eigen::Vector3d::Zero()) *
         cam_from_world;
}

Camera MakeFaceCamera(const int face_size, const double fov_deg) {
  const double half = 0.5 * face_size;
  const double focal = half / std::tan(0.5 * fov_deg * kPi / 180);
  Camera camera;
  camera.model_id = CameraModelId::kPinhole;
  camera.width = static_cast<size_t>(face_size);
  camera.height = static_cast<size_t>(face_size);
  camera.params = {focal, focal, half, half};
  return camera;
}

int AutoFaceSize(const Camera& source, const double fov_deg) {
  const double tan_half = std::tan(0.5 * fov_deg * kPi / 180);
  double focal = 0;
  if (source.model_id == CameraModelId::kEquirectangular) {
    focal = source.width / 8.0;  // w/4 at 90 degrees
  } else {
    // Radians per pixel at the centre: 1 / focal length for COLMAP's models,
    // the model's own pixel angle for the sphere models.
    focal = 1.0 / source.CamFromImgThreshold(1.0);
  }
  const double size = std::round(2 * focal * tan_half);
  if (!std::isfinite(size)) {
    return 2;
  }
  return static_cast<int>(std::max(2.0, std::min(size, 65536.0)));
}

bool IsCubeMappedModel(const CameraModelId model_id) {
  switch (model_id) {
    case CameraModelId::kSimplePinhole:
    case CameraModelId::kPinhole:
    case CameraModelId::kSimpleRadial:
    case CameraModelId::kRadial:
    case CameraModelId::kOpenCV:
    case CameraModelId::kFullOpenCV:
      return false;
    default:
      return true;
  }
}

std::vector<Eigen::Vector3d> OtherLensAxes(const Reconstruction& reconstruction,
                                           const Image& image) {
  std::vector<Eigen::Vector3d> axes;
  if (!image.HasFrameId() || !reconstruction.ExistsFrame(image.FrameId())) {
    return axes;
  }
  const Eigen::Quaterniond cam_from_world = image.CamFromWorld().rotation();
  for (const data_t& data_id :
       reconstruction.Frame(image.FrameId()).ImageIds()) {
    if (data_id.id == image.ImageId() ||
        !reconstruction.ExistsImage(data_id.id)) {
      continue;
    }
    const Image& other = reconstruction.Image(data_id.id);
    if (!other.HasPose()) {
      continue;
    }
    axes.push_back(cam_from_world * (other.CamFromWorld().rotation().inverse() *
                                     Eigen::Vector3d::UnitZ()));
  }
  return axes;
}

bool NearestLens(const std::vector<Eigen::Vector3d>& other_lens_axes,
                 const Eigen::Vector3d& ray) {
  for (const Eigen::Vector3d& axis : other_lens_axes) {
    if (axis.dot(ray) > ray.z()) {
      return false;
    }
  }
  return true;
}

bool ViewPixelToSourcePixel(
    const Camera& source,
    const Camera& view,
    const Eigen::Matrix3d& cam_from_view,
    const Eigen::Vector2d& view_pixel,
    Eigen::Vector2d* source_pixel,
    const std::vector<Eigen::Vector3d>& other_lens_axes) {
  const std::optional<Eigen::Vector3d> ray_in_view =
      PixelRay(view, view_pixel);
  if (!ray_in_view.has_value()) {
    return false;
  }
  const Eigen::Vector3d ray_in_cam = cam_from_view * *ray_in_view;
  if (!NearestLens(other_lens_axes, ray_in_cam)) {
    return false;
  }
  const std::optional<Eigen::Vector2d> pixel = RayPixel(source, ray_in_cam);
  if (!pixel.has_value()) {
    return false;
  }
  *source_pixel = *pixel;
  if (source.model_id == CameraModelId::kEquirectangular) {
    return true;  // every ray is seen; the seam wraps
  }
  if (source_pixel->x() < 0 || source_pixel->y() < 0 ||
      source_pixel->x() > static_cast<double>(source.width) ||
      source_pixel->y() > static_cast<double>(source.height)) {
    return false;
  }
  // Distortion models fold over beyond their field of view: the pixel must
  // see the ray it came from.
  const std::optional<Eigen::Vector3d> back = PixelRay(source, *source_pixel);
  if (!back.has_value()) {
    return false;
  }
  const double tolerance = std::max(1e-6, source.CamFromImgThreshold(1.0));
  return back->dot(ray_in_cam.normalized()) > std::cos(tolerance);
}

RemapMaps BuildRemapMaps(const Camera& source,
                         const Camera& view,
                         const Eigen::Matrix3d& cam_from_view,
                         const std::vector<Eigen::Vector3d>& other_lens_axes) {
  RemapMaps maps;
  const int width = static_cast<int>(view.width);
  const int height = static_cast<int>(view.height);
  maps.map_x.create(height, width, CV_32F);
  maps.map_y.create(height, width, CV_32F);
  size_t num_invalid = 0;
  for (int row = 0; row < height; ++row) {
    float* map_x = maps.map_x.ptr<float>(row);
    float* map_y = maps.map_y.ptr<float>(row);
    for (int col = 0; col < width; ++col) {
      Eigen::Vector2d source_pixel;
      if (ViewPixelToSourcePixel(source,
                                 view,
                                 cam_from_view,
                                 Eigen::Vector2d(col + 0.5, row + 0.5),
                                 &source_pixel,
                                 other_lens_axes)) {
        // COLMAP's pixel centres are at +0.5, OpenCV's at integers.
        map_x[col] = static_cast<float>(source_pixel.x() - 0.5);
        map_y[col] = static_cast<float>(source_pixel.y() - 0.5);
      } else {
        map_x[col] = kInvalidMapValue;
        map_y[col] = kInvalidMapValue;
        ++num_invalid;
      }
    }
  }
  maps.invalid_ratio =
      width * height > 0 ? static_cast<double>(num_invalid) /
                               (static_cast<double>(width) * height)
                         : 1.0;
  return maps;
}

cv::Mat RemapImage(const cv::Mat& source_image,
                   const Camera& source,
                   const RemapMaps& maps) {
  cv::Mat padded;
  if (source.model_id == CameraModelId::kEquirectangular) {
    cv::Mat wrapped;
    cv::copyMakeBorder(source_image,
                       wrapped,
                       0,
                       0,
                       kRemapPadding,
                       kRemapPadding,
                       cv::BORDER_WRAP);
    cv::copyMakeBorder(wrapped,
                       padded,
                       kRemapPadding,
                       kRemapPadding,
                       0,
                       0,
                       cv::BORDER_REPLICATE);
  } else {
    cv::copyMakeBorder(source_image,
                       padded,
                       kRemapPadding,
                       kRemapPadding,
                       kRemapPadding,
                       kRemapPadding,
                       cv::BORDER_REPLICATE);
  }
  // Invalid entries stay far outside the padded image.
  cv::Mat map_x = maps.map_x + kRemapPadding;
  cv::Mat map_y = maps.map_y + kRemapPadding;
  cv::Mat output;
  cv::remap(padded,
            output,
            map_x,
            map_y,
            cv::INTER_LINEAR,
            cv::BORDER_CONSTANT,
            cv::Scalar::all(0));
  return output;
}

SphereExportSummary ExportPerspectiveWorkspace(
    const Reconstruction& reconstruction,
    const std::string& image_path,
    const std::string& output_path,
    const SphereUndistorterOptions& options) {
  Timer timer;
  timer.Start();
  ParsedSphereUndistorterOptions parsed;
  const std::string options_error = options.Parse(&parsed);
  if (!options_error.empty()) {
    throw std::invalid_argument(options_error);
  }

  // Output location.
  fs::path output = fs::path(output_path).lexically_normal();
  if (!output.has_filename() && output.has_parent_path()) {
    output = output.parent_path();  // trailing slash
  }
  if (output.empty()) {
    throw std::invalid_argument("output_path is empty");
  }
  const std::string conflict = OutputConflict(output);
  if (!conflict.empty()) {
    throw std::invalid_argument(conflict);
  }
  const fs::path parent =
      output.has_parent_path() ? output.parent_path() : fs::path(".");
  if (!fs::is_directory(parent)) {
    throw std::invalid_argument("output_path: the parent folder " +
                                parent.string() + " does not exist");
  }

  // Images in name order, every input checked before anything is written.
  std::vector<image_t> image_ids = reconstruction.RegImageIds();
  std::sort(image_ids.begin(),
            image_ids.end(),
            [&](const image_t a, const image_t b) {
              return reconstruction.Image(a).Name() <
                     reconstruction.Image(b).Name();
            });
  if (image_ids.empty()) {
    throw std::invalid_argument("the reconstruction has no registered image");
  }
  const fs::path image_dir(image_path);
  std::map<std::string, std::string> view_sources;
  std::unordered_map<image_t, std::vector<View>> planned;
  for (const image_t image_id : image_ids) {
    const Image& image = reconstruction.Image(image_id);
    const Camera& camera = reconstruction.Camera(image.CameraId());
    const std::string params_error = CameraParamsError(camera);
    if (!params_error.empty()) {
      throw std::invalid_argument("image " + image.Name() + ": camera " +
                                  std::to_string(camera.camera_id) + ": " +
                                  params_error);
    }
    std::vector<View> views = PlanViews(image, camera, options, parsed);
    for (const View& view : views) {
      const auto inserted = view_sources.emplace(view.name, image.Name());
      if (!inserted.second) {
        throw std::invalid_argument("images " + inserted.first->second +
                                    " and " + image.Name() +
                                    " would both write " + view.name);
      }
    }
    planned.emplace(image_id, std::move(views));
  }
  const std::string missing =
      MissingImageFiles(reconstruction, image_ids, image_path);
  if (!missing.empty()) {
    throw std::invalid_argument(missing);
  }

  // Temporary workspace beside the output, moved into place at the end.
  StagedOutput staged;
  const fs::path temp = staged.StageFolder(output);
  const fs::path images_dir = temp / "images";
  const fs::path sparse_dir =
      options.splatting ? temp / "sparse" / "0" : temp / "sparse";
  fs::create_directories(images_dir);
  fs::create_directories(sparse_dir);

  Reconstruction exported;
  std::map<std::vector<double>, camera_t> camera_ids;  // by (w, h, params)
  std::unordered_map<point3D_t, Track> tracks;
  std::vector<std::string> view_names;
  SphereExportSummary summary;
  summary.num_input_images = image_ids.size();

  // Maps of the views of the last source camera (usually one camera) and,
  // with per_frame, of the other lens axes of its frame.
  camera_t cached_camera_id = kInvalidCameraId;
  std::vector<Eigen::Vector3d> cached_other_axes;
  std::map<int, RemapMaps> cached_maps;

  image_t next_image_id = 1;
  for (size_t i = 0; i < image_ids.size(); ++i) {
    const Image& image = reconstruction.Image(image_ids[i]);
    const Camera& camera = reconstruction.Camera(image.CameraId());
    const Rigid3d cam_from_world = image.CamFromWorld();
    const std::string source_path = (image_dir / image.Name()).string();
    cv::Mat source_image;
    try {
      source_image = cv::imread(
          source_path, cv::IMREAD_ANYCOLOR | cv::IMREAD_IGNORE_ORIENTATION);
    } catch (const cv::Exception&) {
      source_image.release();
    }
    if (source_image.empty()) {
      throw std::invalid_argument("image " + image.Name() + ": cannot read " +
                                  source_path);
    }
    if (static_cast<size_t>(source_image.cols) != camera.width ||
        static_cast<size_t>(source_image.rows) != camera.height) {
      std::ostringstream message;
      message << "image " << image.Name() << " is " << source_image.cols
              << "x" << source_image.rows << " but its camera "
              << camera.camera_id << " (" << camera.ModelName() << ") is "
              << camera.width << "x" << camera.height;
      throw std::invalid_argument(message.str());
    }
    // per_frame: the directions this lens leaves to the others of its frame
    // (in a rig the same for every frame, so the maps stay cached).
    const std::vector<Eigen::Vector3d> other_axes =
        options.per_frame ? OtherLensAxes(reconstruction, image)
                          : std::vector<Eigen::Vector3d>();
    bool same_axes = other_axes.size() == cached_other_axes.size();
    for (size_t k = 0; same_axes && k < other_axes.size(); ++k) {
      same_axes = (other_axes[k] - cached_other_axes[k]).norm() < 1e-9;
    }
    if (camera.camera_id != cached_camera_id || !same_axes) {
      cached_maps.clear();
      cached_camera_id = camera.camera_id;
      cached_other_axes = other_axes;
    }
    // The source's mask: its file, or every pixel valid.
    cv::Mat source_mask;
    if (!options.mask_path.empty()) {
      const fs::path mask_file =
          fs::path(options.mask_path) / (image.Name() + ".png");
      if (fs::exists(mask_file)) {
        source_mask = cv::imread(mask_file.string(), cv::IMREAD_GRAYSCALE);
        if (source_mask.empty() || source_mask.cols != source_image.cols ||
            source_mask.rows != source_image.rows) {
          throw std::invalid_argument(
              "mask " + mask_file.string() + " of image " + image.Name() +
              " is unreadable or not the image's size");
        }
      } else {
        source_mask = cv::Mat(source_image.rows, source_image.cols, CV_8U,
                              cv::Scalar(255));
      }
    }

    // Source rays of the 2D points.
    const std::vector<Point2D>& points2D = image.Points2D();
    std::vector<std::optional<Eigen::Vector3d>> rays(points2D.size());
    for (size_t k = 0; k < points2D.size(); ++k) {
      rays[k] = PixelRay(camera, points2D[k].xy);
    }

    size_t num_written = 0;
    for (const View& view : planned.at(image.ImageId())) {
      auto cached = cached_maps.find(view.cache_key);
      if (cached == cached_maps.end()) {
        cached = cached_maps
                     .emplace(view.cache_key,
                              BuildRemapMaps(camera,
                                             view.camera,
                                             view.view_from_cam.transpose(),
                                             cached_other_axes))
                     .first;
      }
      const RemapMaps& maps = cached->second;
      if (view.cache_key >= 0 &&
          maps.invalid_ratio > options.max_invalid_ratio) {
        continue;  // the face sees (almost) nothing of the source image
      }

      // Camera: shared between views of identical intrinsics.
      std::vector<double> key = {static_cast<double>(view.camera.width),
                                 static_cast<double>(view.camera.height)};
      key.insert(
          key.end(), view.camera.params.begin(), view.camera.params.end());
      auto camera_it = camera_ids.find(key);
      if (camera_it == camera_ids.end()) {
        Camera view_camera = view.camera;
        view_camera.camera_id = static_cast<camera_t>(camera_ids.size() + 1);
        const camera_t view_camera_id = view_camera.camera_id;
        exported.AddCameraWithTrivialRig(std::move(view_camera));
        camera_it = camera_ids.emplace(key, view_camera_id).first;
      }

      // Image and its observations.
      const image_t view_image_id = next_image_id++;
      Image view_image;
      view_image.SetImageId(view_image_id);
      view_image.SetName(view.name);
      view_image.SetCameraId(camera_it->second);
      const Rigid3d view_from_world =
          ViewFromWorld(view.view_from_cam, cam_from_world);
      std::vector<Point2D> view_points2D;
      for (size_t k = 0; k < points2D.size(); ++k) {
        if (!rays[k].has_value() || !NearestLens(other_axes, *rays[k])) {
          continue;
        }
        const std::optional<Eigen::Vector2d> xy =
            RayPixel(view.camera, view.view_from_cam * *rays[k]);
        if (!xy.has_value() ||
            !InsideImage(*xy, view.camera.width, view.camera.height)) {
          continue;
        }
        Point2D point2D;
        point2D.xy = *xy;
        if (points2D[k].HasPoint3D()) {
          const Eigen::Vector3d point_in_view =
              view_from_world *
              reconstruction.Point3D(points2D[k].point3D_id).xyz;
          const std::optional<Eigen::Vector2d> projection =
              RayPixel(view.camera, point_in_view);
          if (projection.has_value() &&
              InsideImage(
                  *projection, view.camera.width, view.camera.height)) {
            point2D.point3D_id = points2D[k].point3D_id;
            tracks[point2D.point3D_id].AddElement(
                view_image_id, static_cast<point2D_t>(view_points2D.size()));
            ++summary.num_observations;
          }
        }
        view_points2D.push_back(point2D);
      }
      view_image.SetPoints2D(std::move(view_points2D));

      CreateFolders(images_dir, view.name);
      WriteImage((images_dir / view.name).string(),
                 RemapImage(source_image, camera, maps),
                 options);
      if (!source_mask.empty()) {
        cv::Mat view_mask;
        cv::threshold(RemapImage(source_mask, camera, maps),
                      view_mask,
                      127,
                      255,
                      cv::THRESH_BINARY);
        const fs::path masks_dir = temp / "masks";
        CreateFolders(masks_dir, view.name);
        WriteImage((masks_dir / (view.name + ".png")).string(),
                   view_mask,
                   options);
      }
      exported.AddImageWithTrivialFrame(std::move(view_image),
                                        view_from_world);
      view_names.push_back(view.name);
      ++num_written;
    }
    summary.num_views += num_written;
    LOG(INFO) << "[" << i + 1 << "/" << image_ids.size() << "] "
              << image.Name() << " -> " << num_written
              << (IsCubeMappedModel(camera.model_id) ? " faces"
                                                     : " undistorted view");
  }

  for (auto& [point3D_id, track] : tracks) {
    const Point3D& source_point = reconstruction.Point3D(point3D_id);
    Point3D point;
    point.xyz = source_point.xyz;
    point.color = source_point.color;
    point.error = source_point.error;
    point.track = std::move(track);
    exported.AddPoint3D(point3D_id, std::move(point));
  }
  summary.num_points3D = exported.NumPoints3D();
  exported.WriteBinary(sparse_dir);

  if (!options.splatting) {
    const fs::path stereo_dir = temp / "stereo";
    for (const char* sub :
         {"depth_maps", "normal_maps", "consistency_graphs"}) {
      fs::create_directories(stereo_dir / sub);
      for (const std::string& name : view_names) {
        CreateFolders(stereo_dir / sub, name);
      }
    }
    std::ofstream patch_match(stereo_dir / "patch-match.cfg", std::ios::trunc);
    std::ofstream fusion(stereo_dir / "fusion.cfg", std::ios::trunc);
    for (const std::string& name : view_names) {
      patch_match << name << "\n__auto__, "
                  << options.num_patch_match_src_images << "\n";
      fusion << name << "\n";
    }
    patch_match.close();
    fusion.close();
    if (!patch_match || !fusion) {
      throw std::runtime_error("cannot write the stereo configuration in " +
                               stereo_dir.string());
    }
  }

  summary.num_bytes = FolderBytes(temp);
  const std::string late_conflict = OutputConflict(output);
  if (!late_conflict.empty()) {
    throw std::invalid_argument(late_conflict);
  }
  staged.Commit();
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

std::string MissingImageFiles(const Reconstruction& reconstruction,
                              const std::vector<image_t>& image_ids,
                              const std::string& image_path) {
  std::vector<std::string> missing;
  for (const image_t image_id : image_ids) {
    const std::string& name = reconstruction.Image(image_id).Name();
    const fs::path file = fs::path(image_path) / name;
    std::error_code error;
    if (!fs::is_regular_file(file, error)) {
      missing.push_back(name);
      continue;
    }
    // A JPEG or PNG cut short or overwritten decodes with gray where its
    // data is missing; it is named instead of exported.
    std::ifstream stream(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(stream)),
                            std::istreambuf_iterator<char>());
    if (const std::string damage = ImageBytesError(bytes); !damage.empty()) {
      return "image " + name + ": " + file.string() + " " + damage;
    }
  }
  if (missing.empty()) {
    return "";
  }
  std::ostringstream message;
  message << "image " << missing.front() << " not found in " << image_path;
  if (missing.size() > 1) {
    message << " (and " << missing.size() - 1 << " more missing images)";
  }
  return message.str();
}

std::string ImageUndistorterInputError(
    const Reconstruction& reconstruction,
    const std::vector<image_t>& image_ids,
    const std::filesystem::path& input_path,
    const std::filesystem::path& image_list_path,
    const std::string& image_path) {
  if (reconstruction.NumRegImages() == 0) {
    return "no view to write: the reconstruction at " + input_path.string() +
           " has no registered image";
  }
  if (!image_list_path.empty() && image_ids.empty()) {
    return "no view to write: no image of " + image_list_path.string() +
           " is in the reconstruction";
  }
  const std::vector<image_t> selected =
      image_ids.empty() ? reconstruction.RegImageIds() : image_ids;
  // A camera whose parameters leave no usable projection (a principal
  // point far outside the image, a distortion that cannot be inverted)
  // would fill every view with nothing.
  for (const image_t image_id : selected) {
    if (!reconstruction.ExistsImage(image_id)) continue;
    const Image& image = reconstruction.Image(image_id);
    const Camera& camera = reconstruction.Camera(image.CameraId());
    if (const std::string error = CameraParamsError(camera); !error.empty()) {
      return "image " + image.Name() + ": camera " +
             std::to_string(camera.camera_id) + ": " + error;
    }
  }
  const std::string missing =
      MissingImageFiles(reconstruction, selected, image_path);
  if (!missing.empty()) {
    return missing + " (--image_list_path selects images)";
  }
  return "";
}

}  // namespace colmap
