#include "colmap_ext/scene/camera_params_error.h"

#include "camera_models/projection_check.h"
#include "camera_models/registry.h"

#include <cmath>
#include <sstream>

namespace colmap {

std::string CameraParamsError(const Camera& camera) {
  const CameraModelId model_id = camera.model_id;
  if (!ExistsCameraModelWithId(model_id)) {
    std::ostringstream message;
    message << "unknown camera model id " << static_cast<int>(model_id);
    return message.str();
  }
  const std::string& name = CameraModelIdToName(model_id);
  const std::vector<double>& params = camera.params;
  if (params.size() != CameraModelNumParams(model_id)) {
    std::ostringstream message;
    message << name << " expects " << CameraModelNumParams(model_id)
            << " parameters (" << CameraModelParamsInfo(model_id) << "), got "
            << params.size();
    return message.str();
  }
  if (sphera::IsSphereModel(static_cast<int>(model_id))) {
    // The sphere models (camera_models/registry.h): SPHERA's checks
    // (EQUIRECTANGULAR: w = 2 h and w, h = the image size; Kannala-Brandt:
    // no fold inside the image).
    // Then whether the values, each allowed, leave a projection that can
    // be inverted over the image (no distortion that breaks off or folds,
    // no axis far outside the image).
    const int width = static_cast<int>(camera.width);
    const int height = static_cast<int>(camera.height);
    std::string error = sphera::CheckParams(
        static_cast<int>(model_id), params, width, height);
    if (error.empty()) {
      error = sphera::ProjectionOverImageError(
          static_cast<int>(model_id), params, width, height);
    }
    return error;
  }
  for (const double value : params) {
    if (!std::isfinite(value)) {
      std::ostringstream message;
      message << name << " parameters (" << CameraModelParamsInfo(model_id)
              << ") must be finite";
      return message.str();
    }
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
  // A principal point more than an image size outside the image is no
  // lens's (the sphere models' projection check says the same of their
  // optical axis); upstream's models are otherwise checked as upstream does.
  const span<const size_t> principal_point_idxs =
      CameraModelPrincipalPointIdxs(model_id);
  if (principal_point_idxs.size() == 2 && camera.width > 0 &&
      camera.height > 0) {
    const double cx = params[principal_point_idxs[0]];
    const double cy = params[principal_point_idxs[1]];
    const double width = static_cast<double>(camera.width);
    const double height = static_cast<double>(camera.height);
    if (cx < -width || cx > 2 * width || cy < -height || cy > 2 * height) {
      std::ostringstream message;
      message << name << " principal point (" << cx << ", " << cy
              << ") lies far outside the " << camera.width << "x"
              << camera.height << " image (more than an image size from it)";
      return message.str();
    }
  }
  return "";
}

}  // namespace colmap
