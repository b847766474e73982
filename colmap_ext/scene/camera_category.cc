#include "colmap_ext/scene/camera_category.h"

#include "camera_models/eucm.h"
#include "camera_models/kannala_brandt.h"
#include "camera_models/recent_answers.h"

#include <type_traits>

namespace colmap {
namespace {

// MODEL (camera_models/) with its image in front: the category of UPSTREAM,
// upstream's model struct of the same id.
template <typename Model, typename UpstreamModel>
UpstreamCategory CategoryInFront(const std::vector<double>& params,
                                 const size_t width,
                                 const size_t height) {
  static_assert(static_cast<int>(UpstreamModel::model_id) == Model::kModelId);
  if (params.size() != static_cast<size_t>(Model::kNumParams) ||
      !Model::FieldInFrontOfImagePlane(params.data(),
                                       static_cast<int>(width),
                                       static_cast<int>(height))) {
    return UpstreamCategory::kNone;
  }
  if constexpr (std::is_base_of_v<
                    BasePerspectiveFisheyeCameraModel<UpstreamModel>,
                    UpstreamModel>) {
    return UpstreamCategory::kPerspectiveFisheye;
  } else {
    static_assert(std::is_base_of_v<
                  BasePerspectivePinholeCameraModel<UpstreamModel>,
                  UpstreamModel>);
    return UpstreamCategory::kPerspectivePinhole;
  }
}

// The category of a camera of MODEL_ID with PARAMS in a WIDTH x HEIGHT
// frame (InFrontCameraCategory, its intrinsics the user's).
UpstreamCategory CategoryOf(const CameraModelId model_id,
                            const std::vector<double>& params,
                            const size_t width,
                            const size_t height) {
  switch (static_cast<int>(model_id)) {
    case sphera::OpenCVFisheyeModel::kModelId:
      return CategoryInFront<sphera::OpenCVFisheyeModel,
                             OpenCVFisheyeCameraModel>(params, width, height);
    case sphera::ThinPrismFisheyeModel::kModelId:
      return CategoryInFront<sphera::ThinPrismFisheyeModel,
                             ThinPrismFisheyeCameraModel>(
          params, width, height);
    case sphera::EUCMModel::kModelId:
      return CategoryInFront<sphera::EUCMModel, EUCMCameraModel>(
          params, width, height);
    default:
      return UpstreamCategory::kNone;
  }
}

}  // namespace

UpstreamCategory InFrontCameraCategory(const Camera& camera) {
  if (!camera.has_prior_focal_length) {
    return UpstreamCategory::kNone;
  }
  // Asked for every estimate the camera takes part in; the answer scans its
  // image circle.
  thread_local sphera::RecentAnswers<UpstreamCategory> answers;
  const double key[3] = {static_cast<double>(camera.model_id),
                         static_cast<double>(camera.width),
                         static_cast<double>(camera.height)};
  return answers.Get(key,
                     3,
                     camera.params.data(),
                     camera.params.size(),
                     [&camera] {
                       return CategoryOf(camera.model_id,
                                         camera.params,
                                         camera.width,
                                         camera.height);
                     });
}

}  // namespace colmap
