// Runtime access to the camera models by COLMAP model id.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera_models/double_sphere.h"
#include "camera_models/equirectangular.h"
#include "camera_models/eucm.h"
#include "camera_models/kannala_brandt.h"
#include "camera_models/ocam.h"
#include "camera_models/perspective.h"
#include "camera_models/unified_omni.h"

namespace sphera {

enum class ModelId : int {
  kPinhole = PinholeModel::kModelId,                    // 1
  kOpenCV = OpenCVModel::kModelId,                      // 4
  kOpenCVFisheye = OpenCVFisheyeModel::kModelId,        // 5
  kThinPrismFisheye = ThinPrismFisheyeModel::kModelId,  // 10
  kEUCM = EUCMModel::kModelId,                          // 16
  kEquirectangular = EquirectangularModel::kModelId,    // 17
  kUnifiedOmni = UnifiedOmniModel::kModelId,            // 64
  kDoubleSphere = DoubleSphereModel::kModelId,          // 65
  kOCam = OCamModel::kModelId,                          // 66
};

struct ModelInfo {
  int id;
  const char* name;
  int num_params;
  const char* params_info;
};

namespace internal {

template <typename Model>
ModelInfo InfoOf() {
  return {Model::kModelId, Model::kModelName, Model::kNumParams,
          Model::kParamsInfo};
}

// Calls func(Model{}) for the model with the given id; the single place that
// maps ids to model types.
template <typename Func>
decltype(auto) VisitModel(int model_id, Func&& func) {
  switch (model_id) {
    case PinholeModel::kModelId:
      return func(PinholeModel{});
    case OpenCVModel::kModelId:
      return func(OpenCVModel{});
    case OpenCVFisheyeModel::kModelId:
      return func(OpenCVFisheyeModel{});
    case ThinPrismFisheyeModel::kModelId:
      return func(ThinPrismFisheyeModel{});
    case EUCMModel::kModelId:
      return func(EUCMModel{});
    case EquirectangularModel::kModelId:
      return func(EquirectangularModel{});
    case UnifiedOmniModel::kModelId:
      return func(UnifiedOmniModel{});
    case DoubleSphereModel::kModelId:
      return func(DoubleSphereModel{});
    case OCamModel::kModelId:
      return func(OCamModel{});
    default:
      throw std::invalid_argument("Unknown camera model id " +
                                  std::to_string(model_id));
  }
}

// Guards the raw-pointer model functions against short parameter vectors.
template <typename Model>
void RequireParamCount(const std::vector<double>& params) {
  const std::string error = CheckParamCount(
      Model::kModelName, Model::kParamsInfo, Model::kNumParams, params.size());
  if (!error.empty()) throw std::invalid_argument(error);
}

}  // namespace internal

// The models whose cameras COLMAP hands to SPHERA's own checks and code paths
// (ids 5, 10, 16, 17, 64, 65, 66): every model of this library that COLMAP
// takes through colmap_ext/sensor/sphere_camera_models.h, and
// EQUIRECTANGULAR. Not PINHOLE and OPENCV, which COLMAP keeps handling as
// upstream does. ModelIdFromName and VisitModel know all models.
inline const std::vector<ModelInfo>& SphereModels() {
  static const std::vector<ModelInfo> models = {
      internal::InfoOf<OpenCVFisheyeModel>(),
      internal::InfoOf<ThinPrismFisheyeModel>(),
      internal::InfoOf<EUCMModel>(), internal::InfoOf<EquirectangularModel>(),
      internal::InfoOf<UnifiedOmniModel>(),
      internal::InfoOf<DoubleSphereModel>(), internal::InfoOf<OCamModel>()};
  return models;
}

inline bool IsSphereModel(int model_id) {
  for (const ModelInfo& info : SphereModels()) {
    if (info.id == model_id) return true;
  }
  return false;
}

// Id of a model known to this library (all nine), or -1.
inline int ModelIdFromName(const std::string& name) {
  for (const ModelInfo& info :
       {internal::InfoOf<PinholeModel>(), internal::InfoOf<OpenCVModel>(),
        internal::InfoOf<OpenCVFisheyeModel>(),
        internal::InfoOf<ThinPrismFisheyeModel>(),
        internal::InfoOf<EUCMModel>(), internal::InfoOf<EquirectangularModel>(),
        internal::InfoOf<UnifiedOmniModel>(),
        internal::InfoOf<DoubleSphereModel>(), internal::InfoOf<OCamModel>()}) {
    if (name == info.name) return info.id;
  }
  return -1;
}

// The functions below throw std::invalid_argument for an unknown id and (except
// CheckParams, which reports it) for a wrong number of params.

inline bool ImageFromRay(int model_id, const std::vector<double>& params,
                         const Eigen::Vector3d& ray_in_cam,
                         Eigen::Vector2d* pixel) {
  return internal::VisitModel(model_id, [&](auto model) {
    using Model = decltype(model);
    internal::RequireParamCount<Model>(params);
    return Model::ImageFromRay(params.data(), ray_in_cam.data(),
                               pixel->data());
  });
}

inline bool RayFromImage(int model_id, const std::vector<double>& params,
                         const Eigen::Vector2d& pixel,
                         Eigen::Vector3d* ray_in_cam) {
  return internal::VisitModel(model_id, [&](auto model) {
    using Model = decltype(model);
    internal::RequireParamCount<Model>(params);
    return Model::RayFromImage(params.data(), pixel.data(),
                               ray_in_cam->data());
  });
}

inline double PixelToAngle(int model_id, const std::vector<double>& params) {
  return internal::VisitModel(model_id, [&](auto model) {
    using Model = decltype(model);
    internal::RequireParamCount<Model>(params);
    return Model::PixelToAngle(params.data());
  });
}

inline std::string CheckParams(int model_id, const std::vector<double>& params,
                               int width, int height) {
  return internal::VisitModel(model_id, [&](auto model) {
    using Model = decltype(model);
    return Model::CheckParams(params, width, height);
  });
}

inline std::vector<double> InitialParams(int model_id, double focal_length,
                                         int width, int height) {
  return internal::VisitModel(model_id, [&](auto model) {
    using Model = decltype(model);
    return Model::InitialParams(focal_length, width, height);
  });
}

}  // namespace sphera
