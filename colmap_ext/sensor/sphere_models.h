// COLMAP adapters for the sphere camera models of camera_models/.
//
// This header is included by colmap/sensor/models.h (after BaseCameraModel and
// before CAMERA_MODEL_CASES is used); it is not meant to be included alone.
// Each adapter exposes one camera_models/ struct through COLMAP's static camera
// model interface, so that COLMAP's database, I/O and cost functions see the
// new models like its own. COLMAP's ImgFromCam/CamFromImg already carry a full
// 3D ray (u, v, w); for these models CamFromImg returns the unit bearing ray.
#pragma once

#include "camera_models/double_sphere.h"
#include "camera_models/equirectangular.h"
#include "camera_models/eucm.h"
#include "camera_models/unified_omni.h"

#include <array>
#include <limits>
#include <string>
#include <vector>

namespace colmap {

template <size_t N>
std::array<size_t, N> SphereModelIdxs(const std::array<int, N>& idxs) {
  std::array<size_t, N> out{};
  for (size_t i = 0; i < N; ++i) {
    out[i] = static_cast<size_t>(idxs[i]);
  }
  return out;
}

// Declares COLMAP's camera model members for a camera_models/ struct. The
// static members are defined in models.cc through CAMERA_MODEL_CASES.
#define SPHERA_CAMERA_MODEL_DEFINITIONS(SphereModel)                          \
  using sphere_model = SphereModel;                                          \
  static constexpr size_t num_params = SphereModel::kNumParams;              \
  static constexpr size_t num_focal_params =                                 \
      SphereModel::kFocalLengthIdxs.size();                                   \
  static constexpr size_t num_pp_params =                                    \
      SphereModel::kPrincipalPointIdxs.size();                                \
  static constexpr size_t num_extra_params =                                 \
      SphereModel::kExtraParamsIdxs.size();                                   \
  static constexpr CameraModelId model_id =                                  \
      static_cast<CameraModelId>(SphereModel::kModelId);                      \
  static const std::string model_name;                                       \
  static const std::string params_info;                                      \
  static const std::array<size_t, num_focal_params> focal_length_idxs;       \
  static const std::array<size_t, num_pp_params> principal_point_idxs;       \
  static const std::array<size_t, num_extra_params> extra_params_idxs;       \
                                                                             \
  static inline CameraModelId InitializeModelId() { return model_id; }       \
  static inline std::string InitializeModelName() {                          \
    return SphereModel::kModelName;                                           \
  }                                                                          \
  static inline std::string InitializeParamsInfo() {                         \
    return SphereModel::kParamsInfo;                                          \
  }                                                                          \
  static inline std::array<size_t, num_focal_params>                         \
  InitializeFocalLengthIdxs() {                                               \
    return SphereModelIdxs(SphereModel::kFocalLengthIdxs);                    \
  }                                                                          \
  static inline std::array<size_t, num_pp_params>                            \
  InitializePrincipalPointIdxs() {                                            \
    return SphereModelIdxs(SphereModel::kPrincipalPointIdxs);                 \
  }                                                                          \
  static inline std::array<size_t, num_extra_params>                         \
  InitializeExtraParamsIdxs() {                                               \
    return SphereModelIdxs(SphereModel::kExtraParamsIdxs);                    \
  }                                                                          \
  static inline std::vector<double> InitializeParams(                        \
      double focal_length, size_t width, size_t height) {                     \
    return SphereModel::InitialParams(focal_length,                           \
                                      static_cast<int>(width),                \
                                      static_cast<int>(height));              \
  }                                                                          \
  /* The pixel is written wherever the formula is defined; visibility is  */ \
  /* reported by CameraModelImgFromCamRay.                                 */ \
  template <typename T>                                                       \
  static void ImgFromCam(const T* params, T u, T v, T w, T* x, T* y) {       \
    const T ray_in_cam[3] = {u, v, w};                                        \
    T pixel[2] = {T(0), T(0)};                                                \
    SphereModel::ImageFromRay(params, ray_in_cam, pixel);                     \
    *x = pixel[0];                                                            \
    *y = pixel[1];                                                            \
  }                                                                          \
  /* Unit bearing ray; NaN outside the model's image domain.               */ \
  template <typename T>                                                       \
  static void CamFromImg(const T* params, T x, T y, T* u, T* v, T* w) {      \
    const T pixel[2] = {x, y};                                                \
    T ray_in_cam[3];                                                          \
    if (!SphereModel::RayFromImage(params, pixel, ray_in_cam)) {              \
      ray_in_cam[0] = ray_in_cam[1] = ray_in_cam[2] =                         \
          T(std::numeric_limits<double>::quiet_NaN());                        \
    }                                                                        \
    *u = ray_in_cam[0];                                                       \
    *v = ray_in_cam[1];                                                       \
    *w = ray_in_cam[2];                                                       \
  }                                                                          \
  /* Pixel thresholds become angles (radians) on the unit sphere.          */ \
  template <typename T>                                                       \
  static T CamFromImgThreshold(const T* params, T threshold) {               \
    return threshold * T(SphereModel::PixelToAngle(params));                  \
  }                                                                          \
  template <typename T>                                                       \
  static bool HasBogusParams(const std::vector<T>& params,                   \
                             size_t width,                                    \
                             size_t height,                                   \
                             T /*min_focal_length_ratio*/,                    \
                             T /*max_focal_length_ratio*/,                    \
                             T /*max_extra_param*/) {                         \
    return !SphereModel::CheckParams(                                         \
                params, static_cast<int>(width), static_cast<int>(height))    \
                .empty();                                                     \
  }

// Enhanced unified camera model (Khomenko et al. 2016), id 16.
struct EUCMCameraModel : public BaseCameraModel<EUCMCameraModel> {
  SPHERA_CAMERA_MODEL_DEFINITIONS(sphera::EUCMModel)
};

// Equirectangular 360° panorama, id 17, upstream COLMAP 4.1's convention.
struct EquirectangularCameraModel
    : public BaseCameraModel<EquirectangularCameraModel> {
  SPHERA_CAMERA_MODEL_DEFINITIONS(sphera::EquirectangularModel)
};

// Mei's unified omnidirectional model with radial-tangential distortion, id 64.
struct UnifiedOmniCameraModel
    : public BaseCameraModel<UnifiedOmniCameraModel> {
  SPHERA_CAMERA_MODEL_DEFINITIONS(sphera::UnifiedOmniModel)
};

// Double sphere model (Usenko et al. 2018), id 65.
struct DoubleSphereCameraModel
    : public BaseCameraModel<DoubleSphereCameraModel> {
  SPHERA_CAMERA_MODEL_DEFINITIONS(sphera::DoubleSphereModel)
};

#define SPHERA_CAMERA_MODEL_CASES               \
  CAMERA_MODEL_CASE(EUCMCameraModel)            \
  CAMERA_MODEL_CASE(EquirectangularCameraModel) \
  CAMERA_MODEL_CASE(UnifiedOmniCameraModel)     \
  CAMERA_MODEL_CASE(DoubleSphereCameraModel)

// True for the models of camera_models/ (rays anywhere on the sphere).
bool CameraModelIsSphere(CameraModelId model_id);

// Parameters that are never refined (e.g. EQUIRECTANGULAR's w, h).
std::vector<size_t> CameraModelFixedParamsIdxs(CameraModelId model_id);

// Unit bearing ray of a pixel, for every model. False when the pixel is
// outside the model's image domain or the ray is not finite.
bool CameraModelCamRayFromImg(CameraModelId model_id,
                              const std::vector<double>& params,
                              const Eigen::Vector2d& image_point,
                              Eigen::Vector3d* ray_in_cam);

// Pixel of a ray, for every model. False ("not visible") when the ray is
// outside the field of view: behind the image plane for COLMAP's own models,
// outside the model's domain for the sphere models.
bool CameraModelImgFromCamRay(CameraModelId model_id,
                              const std::vector<double>& params,
                              const Eigen::Vector3d& ray_in_cam,
                              Eigen::Vector2d* image_point);

// Radians per pixel at the image centre: converts pixel thresholds to angles.
double CameraModelPixelToAngle(CameraModelId model_id,
                               const std::vector<double>& params);

// Empty when the parameters are valid for the model (and, when width and
// height are non-zero, for an image of that size); otherwise a message that
// names the model and the offending parameter.
std::string CameraModelParamsError(CameraModelId model_id,
                                   const std::vector<double>& params,
                                   size_t width,
                                   size_t height);

}  // namespace colmap
