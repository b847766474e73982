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
    // EUCM, EQUIRECTANGULAR, UNIFIED_OMNI, DOUBLE_SPHERE: SPHERA's checks
    // (EQUIRECTANGULAR: w = 2 h and w, h = the image size).
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
  return "";
}

}  // namespace colmap
