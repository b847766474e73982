// Runtime dispatch over every camera model for ray lifting, visibility,
// threshold conversion and parameter checks (declared in sphere_models.h).
#include "colmap/sensor/models.h"

#include <cmath>
#include <sstream>

namespace colmap {
namespace {

// Rays closer than this to the image plane of a plane-based model (COLMAP's
// own models) are "not visible": their projection is unbounded.
constexpr double kMinPlaneDepth = 1e-12;

bool AllFinite(const std::vector<double>& values) {
  for (const double value : values) {
    if (!std::isfinite(value)) {
      return false;
    }
  }
  return true;
}

}  // namespace

bool CameraModelIsSphere(const CameraModelId model_id) {
  switch (model_id) {
#define CAMERA_MODEL_CASE(CameraModel) \
  case CameraModel::model_id:          \
    return true;
    SPHERA_CAMERA_MODEL_CASES
#undef CAMERA_MODEL_CASE
    default:
      return false;
  }
}

std::vector<size_t> CameraModelFixedParamsIdxs(const CameraModelId model_id) {
  switch (model_id) {
#define CAMERA_MODEL_CASE(CameraModel)                                 \
  case CameraModel::model_id: {                                        \
    const auto& idxs = CameraModel::sphere_model::kFixedParamsIdxs;    \
    return std::vector<size_t>(idxs.begin(), idxs.end());              \
  }
    SPHERA_CAMERA_MODEL_CASES
#undef CAMERA_MODEL_CASE
    default:
      return {};
  }
}

bool CameraModelCamRayFromImg(const CameraModelId model_id,
                              const std::vector<double>& params,
                              const Eigen::Vector2d& image_point,
                              Eigen::Vector3d* ray_in_cam) {
  switch (model_id) {
#define CAMERA_MODEL_CASE(CameraModel)                                      \
  case CameraModel::model_id:                                               \
    if (!CameraModel::sphere_model::RayFromImage(                           \
            params.data(), image_point.data(), ray_in_cam->data())) {       \
      return false;                                                         \
    }                                                                       \
    break;
    SPHERA_CAMERA_MODEL_CASES
#undef CAMERA_MODEL_CASE
    default:
      *ray_in_cam = CameraModelCamFromImg(model_id, params, image_point);
  }
  const double norm = ray_in_cam->norm();
  if (!std::isfinite(norm) || norm == 0) {
    return false;
  }
  *ray_in_cam /= norm;
  return true;
}

bool CameraModelImgFromCamRay(const CameraModelId model_id,
                              const std::vector<double>& params,
                              const Eigen::Vector3d& ray_in_cam,
                              Eigen::Vector2d* image_point) {
  if (!ray_in_cam.allFinite()) {
    return false;
  }
  switch (model_id) {
#define CAMERA_MODEL_CASE(CameraModel)                                 \
  case CameraModel::model_id:                                          \
    return CameraModel::sphere_model::ImageFromRay(                    \
               params.data(), ray_in_cam.data(), image_point->data()) && \
           image_point->allFinite();
    SPHERA_CAMERA_MODEL_CASES
#undef CAMERA_MODEL_CASE
    default:
      if (ray_in_cam.z() <= kMinPlaneDepth * ray_in_cam.norm()) {
        return false;
      }
      *image_point = CameraModelImgFromCam(model_id, params, ray_in_cam);
      return image_point->allFinite();
  }
}

double CameraModelPixelToAngle(const CameraModelId model_id,
                               const std::vector<double>& params) {
  // For COLMAP's own models one pixel at the centre spans 1 / f radians,
  // which is exactly their CamFromImgThreshold.
  return CameraModelCamFromImgThreshold(model_id, params, 1.0);
}

std::string CameraModelParamsError(const CameraModelId model_id,
                                   const std::vector<double>& params,
                                   const size_t width,
                                   const size_t height) {
  if (!ExistsCameraModelWithId(model_id)) {
    std::ostringstream message;
    message << "unknown camera model id " << static_cast<int>(model_id);
    return message.str();
  }
  const std::string& name = CameraModelIdToName(model_id);
  if (params.size() != CameraModelNumParams(model_id)) {
    std::ostringstream message;
    message << name << " expects " << CameraModelNumParams(model_id)
            << " parameters (" << CameraModelParamsInfo(model_id)
            << "), got " << params.size();
    return message.str();
  }
  switch (model_id) {
#define CAMERA_MODEL_CASE(CameraModel)                          \
  case CameraModel::model_id:                                   \
    return CameraModel::sphere_model::CheckParams(              \
        params, static_cast<int>(width), static_cast<int>(height));
    SPHERA_CAMERA_MODEL_CASES
#undef CAMERA_MODEL_CASE
    default:
      break;
  }
  if (!AllFinite(params)) {
    std::ostringstream message;
    message << name << " parameters (" << CameraModelParamsInfo(model_id)
            << ") must be finite";
    return message.str();
  }
  for (const size_t idx : CameraModelFocalLengthIdxs(model_id)) {
    if (params[idx] <= 0) {
      std::ostringstream message;
      message << name << " focal length (parameter " << idx + 1 << " of "
              << CameraModelParamsInfo(model_id) << ") must be positive, got "
              << params[idx];
      return message.str();
    }
  }
  return "";
}

}  // namespace colmap
