#include "colmap_ext/scene/intrinsics_divergence.h"

#include "colmap/util/logging.h"

#include <cmath>
#include <limits>
#include <sstream>

namespace colmap {

std::string IntrinsicsDivergence(const Camera& prior,
                                 const Camera& refined,
                                 const IntrinsicsDivergenceOptions& options) {
  std::ostringstream why;
  for (const double value : refined.params) {
    if (!std::isfinite(value)) {
      why << "a parameter is not finite (" << refined.ParamsToString() << ")";
      return why.str();
    }
  }
  // Only the model's own validity (SPHERA's sphere models check their
  // parameter ranges; COLMAP's models their focal length and principal
  // point), not COLMAP's focal-ratio heuristics.
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (refined.HasBogusParams(0, kInf, kInf)) {
    why << "the parameters left the valid range of " << refined.ModelName()
        << " (" << refined.ParamsToString() << ")";
    return why.str();
  }
  if (prior.model_id != refined.model_id ||
      refined.FocalLengthIdxs().empty()) {
    return "";
  }
  const double ratio = refined.MeanFocalLength() / prior.MeanFocalLength();
  if (!(ratio <= options.max_focal_ratio &&
        ratio >= 1 / options.max_focal_ratio)) {
    why << "the focal length went from " << prior.MeanFocalLength() << " to "
        << refined.MeanFocalLength() << " pixels";
    if (refined.FocalLengthIdxs().size() > 1) {
      why << " (fx " << refined.FocalLengthX() << ", fy "
          << refined.FocalLengthY() << ")";
    }
    return why.str();
  }
  if (refined.FocalLengthIdxs().size() > 1 &&
      prior.FocalLengthX() == prior.FocalLengthY()) {
    const double aspect = refined.FocalLengthX() / refined.FocalLengthY();
    if (std::abs(aspect - 1) > options.max_aspect_change) {
      why << "a square-pixel lens ended with fx / fy = " << aspect << " (fx "
          << refined.FocalLengthX() << ", fy " << refined.FocalLengthY()
          << ")";
      return why.str();
    }
  }
  if (!refined.PrincipalPointIdxs().empty()) {
    const double x = refined.PrincipalPointX(), y = refined.PrincipalPointY();
    if (x < 0 || y < 0 || x > refined.width || y > refined.height) {
      why << "the principal point (" << x << ", " << y
          << ") left the image";
      return why.str();
    }
  }
  return "";
}

void DivergedCameraHold::Remember(const Reconstruction& reconstruction) {
  params_before_.clear();
  for (const auto& [camera_id, camera] : reconstruction.Cameras()) {
    params_before_.emplace(camera_id, camera.params);
  }
}

void DivergedCameraHold::HoldDiverged(const DatabaseCache& database_cache,
                               const IntrinsicsDivergenceOptions& options,
                               Reconstruction* reconstruction) {
  for (const auto& [camera_id, before] : params_before_) {
    if (held_ids_.count(camera_id) || !database_cache.ExistsCamera(camera_id)) {
      continue;
    }
    Camera& camera = reconstruction->Camera(camera_id);
    const std::string why =
        IntrinsicsDivergence(database_cache.Camera(camera_id), camera, options);
    if (why.empty()) {
      continue;
    }
    camera.params = before;
    LOG(WARNING) << "Camera " << camera_id << " (" << camera.ModelName()
                 << "): its self-calibration ran away: " << why
                 << ". Held at its value before this bundle adjustment ("
                 << camera.ParamsToString() << ") and no longer refined.";
    held_ids_.insert(camera_id);
    held_.push_back({camera, why});
  }
}

std::unordered_set<camera_t> DivergedCameraHold::ConstantIntrinsics(
    const Reconstruction& reconstruction,
    const FlatHashMap<camera_t, size_t>& num_reg_images_per_camera,
    const IntrinsicsDivergenceOptions& options) const {
  std::unordered_set<camera_t> constant = held_ids_;
  for (const auto& [rig_id, rig] : reconstruction.Rigs()) {
    if (rig.NumSensors() < 2) {
      continue;
    }
    for (const sensor_t& sensor_id : rig.SensorIds()) {
      if (sensor_id.type != SensorType::CAMERA) {
        continue;
      }
      const auto found = num_reg_images_per_camera.find(sensor_id.id);
      const size_t num_images =
          found == num_reg_images_per_camera.end() ? 0 : found->second;
      if (num_images < static_cast<size_t>(options.min_rig_frames)) {
        constant.insert(sensor_id.id);
      }
    }
  }
  return constant;
}

}  // namespace colmap
