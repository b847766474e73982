#include "colmap_ext/controllers/model_evaluation.h"

#include "colmap/estimators/alignment.h"
#include "colmap/estimators/solvers/similarity_transform.h"
#include "colmap/geometry/pose.h"
#include "colmap/math/math.h"
#include "colmap/util/logging.h"
#include "colmap/util/string.h"
#include "colmap_ext/controllers/sphere_bundle_adjustment.h"
#include "estimators/similarity_alignment.h"
#include "synthetic/file_formats.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <iomanip>
#include <sstream>
#include <unordered_map>

namespace colmap {
namespace {

using sphera::RangeMap;
using sphera::ReadRangeMap;

// sphera_render's range map of one image (synthetic/file_formats.h).
struct DepthMap {
  RangeMap map;

  // Empty, or why the file at `path` is not the range map of an image of
  // `camera`'s size: unreadable, damaged, another size, or holding a range
  // that is negative or not finite (a damaged file would bias every point
  // error).
  std::string Read(const std::string& path, const Camera& camera) {
    if (std::string error = ReadRangeMap(path, &map); !error.empty()) {
      return error;
    }
    if (map.width != static_cast<int64_t>(camera.width) ||
        map.height != static_cast<int64_t>(camera.height)) {
      return "is " + std::to_string(map.width) + "x" +
             std::to_string(map.height) + ", its image " +
             std::to_string(camera.width) + "x" +
             std::to_string(camera.height);
    }
    return "";
  }

  // Range along the ray through `point2D`: bilinear between the four
  // surrounding pixel centres on a smooth surface (ranges within 2% of each
  // other), else the range of the pixel containing it; 0 outside or without a
  // hit. Interpolation removes most of the half-pixel footprint that the
  // nearest pixel would add to the 3D point error.
  double At(const Eigen::Vector2d& point2D) const {
    const int x = static_cast<int>(std::floor(point2D.x()));
    const int y = static_cast<int>(std::floor(point2D.y()));
    if (x < 0 || y < 0 || x >= map.width || y >= map.height) {
      return 0;
    }
    const double nearest = Range(x, y);
    const double u = point2D.x() - 0.5;
    const double v = point2D.y() - 0.5;
    const int x0 = static_cast<int>(std::floor(u));
    const int y0 = static_cast<int>(std::floor(v));
    if (x0 < 0 || y0 < 0 || x0 + 1 >= map.width || y0 + 1 >= map.height) {
      return nearest;
    }
    const double r00 = Range(x0, y0);
    const double r10 = Range(x0 + 1, y0);
    const double r01 = Range(x0, y0 + 1);
    const double r11 = Range(x0 + 1, y0 + 1);
    const double r_min = std::min({r00, r10, r01, r11});
    const double r_max = std::max({r00, r10, r01, r11});
    if (r_min <= 0 || r_max > 1.02 * r_min) {
      return nearest;
    }
    const double a = u - x0;
    const double b = v - y0;
    return (1 - b) * ((1 - a) * r00 + a * r10) + b * ((1 - a) * r01 + a * r11);
  }

 private:
  double Range(int x, int y) const { return map.At(x, y); }
};

double ClosestPairBaseline(const Reconstruction& reconstruction) {
  std::vector<Eigen::Vector3d> centers;
  for (const image_t image_id : reconstruction.RegImageIds()) {
    centers.push_back(reconstruction.Image(image_id).ProjectionCenter());
  }
  double closest = std::numeric_limits<double>::max();
  double largest = 0;
  for (size_t i = 0; i < centers.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      const double distance = (centers[i] - centers[j]).norm();
      closest = std::min(closest, distance);
      largest = std::max(largest, distance);
    }
  }
  return centers.size() < 2 ? 0 : closest;
}

double LargestBaseline(const Reconstruction& reconstruction) {
  double largest = 0;
  const std::vector<image_t>& image_ids = reconstruction.RegImageIds();
  for (size_t i = 0; i < image_ids.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      largest = std::max(
          largest,
          (reconstruction.Image(image_ids[i]).ProjectionCenter() -
           reconstruction.Image(image_ids[j]).ProjectionCenter())
              .norm());
    }
  }
  return largest;
}

std::string JsonNumber(double value) {
  if (!std::isfinite(value)) {
    return "null";
  }
  std::ostringstream out;
  out << std::setprecision(10) << value;
  return out.str();
}

std::string JsonString(const std::string& value) {
  std::string out = "\"";
  for (const char c : value) {
    if (c == '"' || c == '\\') {
      out += '\\';
    }
    out += c;
  }
  return out + "\"";
}

}  // namespace

ModelEvaluation EvaluateModel(const Reconstruction& ground_truth,
                              const Reconstruction& reconstruction,
                              const ModelEvaluationOptions& options) {
  ModelEvaluation evaluation;
  evaluation.num_gt_images = ground_truth.NumRegImages();
  evaluation.num_points3D = reconstruction.NumPoints3D();

  const std::vector<std::pair<image_t, image_t>> common_image_ids =
      reconstruction.FindCommonRegImageIds(ground_truth);
  evaluation.num_registered = common_image_ids.size();
  if (common_image_ids.size() < 3) {
    throw std::invalid_argument(
        StringPrintf("only %d registered images in common with the ground "
                     "truth; at least 3 are needed to align",
                     static_cast<int>(common_image_ids.size())));
  }

  if (const std::string error = options.Check(); !error.empty()) {
    throw std::invalid_argument(error);
  }
  double max_proj_center_error = options.max_proj_center_error;
  if (max_proj_center_error == 0) {
    max_proj_center_error = 0.05 * LargestBaseline(ground_truth);
  }
  if (!(max_proj_center_error > 0)) {
    throw std::invalid_argument(
        "the ground-truth camera centres coincide; cannot align by centres");
  }
  Sim3d gt_from_reconstruction;
  if (!AlignReconstructionsViaProjCenters(reconstruction,
                                          ground_truth,
                                          max_proj_center_error,
                                          &gt_from_reconstruction)) {
    throw std::invalid_argument(
        "no similarity aligns the camera centres within " +
        std::to_string(max_proj_center_error) + " (ground-truth units)");
  }

  // Refine on the centres that the robust alignment kept.
  std::vector<Eigen::Matrix3d> world_rotations;
  std::vector<Eigen::Vector3d> inlier_centers;
  std::vector<Eigen::Vector3d> inlier_gt_centers;
  for (const auto& [image_id, gt_image_id] : common_image_ids) {
    const Image& image = reconstruction.Image(image_id);
    const Image& gt_image = ground_truth.Image(gt_image_id);
    world_rotations.push_back(
        gt_image.CamFromWorld().rotation().toRotationMatrix().transpose() *
        image.CamFromWorld().rotation().toRotationMatrix());
    if ((gt_from_reconstruction * image.ProjectionCenter() -
         gt_image.ProjectionCenter())
            .norm() <= max_proj_center_error) {
      inlier_centers.push_back(image.ProjectionCenter());
      inlier_gt_centers.push_back(gt_image.ProjectionCenter());
    }
  }
  evaluation.alignment = options.alignment;
  switch (options.alignment) {
    case ModelAlignment::CENTERS: {
      Sim3d least_squares;
      if (EstimateSim3d(inlier_centers, inlier_gt_centers, least_squares)) {
        gt_from_reconstruction = least_squares;
      }
      break;
    }
    case ModelAlignment::ORIENTATIONS: {
      // The geodesic median is robust to a minority of wrong cameras.
      const Eigen::Matrix3d gt_from_reconstruction_rotation =
          sphera::GeodesicMedianRotation(world_rotations);
      double scale = 0;
      Eigen::Vector3d translation;
      if (sphera::AlignCentersWithRotation(inlier_centers,
                                           inlier_gt_centers,
                                           gt_from_reconstruction_rotation,
                                           &scale,
                                           &translation)) {
        gt_from_reconstruction =
            Sim3d(scale,
                  Eigen::Quaterniond(gt_from_reconstruction_rotation),
                  translation);
      }
      break;
    }
  }

  evaluation.gt_from_reconstruction = gt_from_reconstruction;
  evaluation.closest_pair_baseline = ClosestPairBaseline(ground_truth);
  const std::vector<ImageAlignmentError> alignment_errors =
      ComputeImageAlignmentError(
          reconstruction, ground_truth, gt_from_reconstruction);
  std::unordered_map<std::string, ImageAlignmentError> errors_by_name;
  for (const ImageAlignmentError& error : alignment_errors) {
    errors_by_name[error.image_name] = error;
  }
  for (const image_t image_id : ground_truth.RegImageIds()) {
    ImageEvaluation image;
    image.name = ground_truth.Image(image_id).Name();
    const auto it = errors_by_name.find(image.name);
    if (it != errors_by_name.end()) {
      image.registered = true;
      image.rotation_error_deg = it->second.rotation_error_deg;
      image.position_error = it->second.proj_center_error;
      image.position_error_normalized =
          evaluation.closest_pair_baseline > 0
              ? image.position_error / evaluation.closest_pair_baseline
              : -1;
      evaluation.mean_rotation_error_deg += image.rotation_error_deg;
      evaluation.max_rotation_error_deg =
          std::max(evaluation.max_rotation_error_deg, image.rotation_error_deg);
      evaluation.mean_position_error += image.position_error;
      evaluation.max_position_error =
          std::max(evaluation.max_position_error, image.position_error);
      evaluation.mean_position_error_normalized +=
          image.position_error_normalized;
    }
    evaluation.images.push_back(image);
  }
  evaluation.mean_rotation_error_deg /= evaluation.num_registered;
  evaluation.mean_position_error /= evaluation.num_registered;
  evaluation.mean_position_error_normalized /= evaluation.num_registered;

  // Angular reprojection error over all observations, per camera too.
  for (const auto& [camera_id, error] :
       AngularErrorsByCamera(reconstruction)) {
    CameraEvaluation camera_evaluation;
    camera_evaluation.camera_id = camera_id;
    camera_evaluation.model_name = reconstruction.Camera(camera_id).ModelName();
    camera_evaluation.num_observations = error.num_observations;
    camera_evaluation.mean_angular_error_rad =
        error.sum_rad / error.num_observations;
    camera_evaluation.mean_angular_error_px =
        error.sum_px / error.num_observations;
    evaluation.cameras.push_back(camera_evaluation);
  }
  MeanAngularError(reconstruction,
                   &evaluation.num_observations,
                   &evaluation.mean_angular_error_rad,
                   &evaluation.mean_angular_error_px);

  // 3D point error against the ground-truth range maps: the true surface
  // point on the observed ray of a ground-truth camera.
  if (!options.depth_path.empty()) {
    std::unordered_map<std::string, DepthMap> depth_maps;
    std::unordered_map<std::string, image_t> gt_image_ids;
    for (const image_t image_id : ground_truth.RegImageIds()) {
      const std::string& name = ground_truth.Image(image_id).Name();
      DepthMap depth_map;
      const std::string depth_file =
          (std::filesystem::path(options.depth_path) / (name + ".depth.bin"))
              .string();
      const Camera& camera =
          ground_truth.Camera(ground_truth.Image(image_id).CameraId());
      if (const std::string error = depth_map.Read(depth_file, camera);
          !error.empty()) {
        throw std::invalid_argument("--depth_path: depth map " + depth_file +
                                    " " + error);
      }
      depth_maps.emplace(name, std::move(depth_map));
      gt_image_ids.emplace(name, image_id);
    }
    std::vector<double> point_errors;
    for (const auto& [point3D_id, point3D] : reconstruction.Points3D()) {
      const Eigen::Vector3d point_in_gt = gt_from_reconstruction * point3D.xyz;
      for (const TrackElement& element : point3D.track.Elements()) {
        const Image& image = reconstruction.Image(element.image_id);
        const auto gt_it = gt_image_ids.find(image.Name());
        if (gt_it == gt_image_ids.end()) {
          continue;
        }
        const Image& gt_image = ground_truth.Image(gt_it->second);
        const Camera& gt_camera = ground_truth.Camera(gt_image.CameraId());
        const Eigen::Vector2d& xy = image.Point2D(element.point2D_idx).xy;
        const double range = depth_maps.at(image.Name()).At(xy);
        const std::optional<Eigen::Vector3d> ray_in_cam =
            range > 0 ? gt_camera.CamRayFromImg(xy) : std::nullopt;
        if (!ray_in_cam) {
          continue;
        }
        const Rigid3d world_from_cam = Inverse(gt_image.CamFromWorld());
        const Eigen::Vector3d surface_point =
            world_from_cam * (range * *ray_in_cam);
        point_errors.push_back((point_in_gt - surface_point).norm());
        break;
      }
    }
    evaluation.num_points_with_depth = point_errors.size();
    if (!point_errors.empty()) {
      evaluation.mean_point_error = Mean(point_errors);
      evaluation.median_point_error = Median(point_errors);
    }
  }
  return evaluation;
}

std::string ModelEvaluationOptions::Check() const {
  if (!(max_proj_center_error >= 0) || !std::isfinite(max_proj_center_error)) {
    return "--max_proj_center_error must be >= 0 (0: 5% of the largest "
           "ground-truth baseline), got " +
           std::to_string(max_proj_center_error);
  }
  return "";
}

std::string AlignmentName(ModelAlignment alignment) {
  std::string name(ModelAlignmentToString(alignment));
  StringToLower(&name);
  return name;
}

std::string ModelEvaluationToJson(const ModelEvaluation& e) {
  std::ostringstream json;
  json << "{\n"
       << "  \"alignment\": " << JsonString(AlignmentName(e.alignment))
       << ",\n"
       << "  \"num_gt_images\": " << e.num_gt_images << ",\n"
       << "  \"num_registered\": " << e.num_registered << ",\n"
       << "  \"num_points3D\": " << e.num_points3D << ",\n"
       << "  \"closest_pair_baseline\": "
       << JsonNumber(e.closest_pair_baseline) << ",\n"
       << "  \"mean_rotation_error_deg\": "
       << JsonNumber(e.mean_rotation_error_deg) << ",\n"
       << "  \"max_rotation_error_deg\": "
       << JsonNumber(e.max_rotation_error_deg) << ",\n"
       << "  \"mean_position_error\": " << JsonNumber(e.mean_position_error)
       << ",\n"
       << "  \"max_position_error\": " << JsonNumber(e.max_position_error)
       << ",\n"
       << "  \"mean_position_error_normalized\": "
       << JsonNumber(e.mean_position_error_normalized) << ",\n"
       << "  \"num_observations\": " << e.num_observations << ",\n"
       << "  \"mean_angular_error_rad\": "
       << JsonNumber(e.mean_angular_error_rad) << ",\n"
       << "  \"mean_angular_error_px\": " << JsonNumber(e.mean_angular_error_px)
       << ",\n"
       << "  \"num_points_with_depth\": " << e.num_points_with_depth << ",\n"
       << "  \"mean_point_error\": " << JsonNumber(e.mean_point_error) << ",\n"
       << "  \"median_point_error\": " << JsonNumber(e.median_point_error)
       << ",\n"
       << "  \"cameras\": [";
  for (size_t i = 0; i < e.cameras.size(); ++i) {
    const CameraEvaluation& c = e.cameras[i];
    json << (i ? ",\n" : "\n") << "    {\"camera_id\": " << c.camera_id
         << ", \"model\": " << JsonString(c.model_name)
         << ", \"num_observations\": " << c.num_observations
         << ", \"mean_angular_error_rad\": "
         << JsonNumber(c.mean_angular_error_rad)
         << ", \"mean_angular_error_px\": "
         << JsonNumber(c.mean_angular_error_px) << "}";
  }
  json << "\n  ],\n  \"images\": [";
  for (size_t i = 0; i < e.images.size(); ++i) {
    const ImageEvaluation& image = e.images[i];
    json << (i ? ",\n" : "\n") << "    {\"name\": " << JsonString(image.name)
         << ", \"registered\": " << (image.registered ? "true" : "false")
         << ", \"rotation_error_deg\": "
         << JsonNumber(image.rotation_error_deg)
         << ", \"position_error\": " << JsonNumber(image.position_error)
         << ", \"position_error_normalized\": "
         << JsonNumber(image.position_error_normalized) << "}";
  }
  json << "\n  ]\n}\n";
  return json.str();
}

}  // namespace colmap
