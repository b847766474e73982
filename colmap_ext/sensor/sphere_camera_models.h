// COLMAP 4.x adapters for the camera models of camera_models/ whose field of
// view may exceed a hemisphere: OPENCV_FISHEYE (5), THIN_PRISM_FISHEYE (10)
// and EUCM (16) with upstream's ids, parameters and file formats but over the
// model's whole field of view (rays behind the image plane included), and
// UNIFIED_OMNI (64), DOUBLE_SPHERE (65) and OCAM (66).
//
// colmap/sensor/models.h includes this header after its own model structs,
// as it includes models_jacobian.h at its end; it needs nothing else from
// COLMAP and includes only camera_models/ and Ceres.
//
// In COLMAP's taxonomy these models are spherical (IsSpherical(): rays on the
// whole sphere, cheirality along the ray, errors as angles) with the parameter
// groups of a perspective model (focal length, principal point and extra
// parameters, refinable in bundle adjustment) and no metadata parameters;
// OCAM has no focal length (its polynomial's a0 plays that part).
#pragma once

#include "camera_models/double_sphere.h"
#include "camera_models/eucm.h"
#include "camera_models/kannala_brandt.h"
#include "camera_models/ocam.h"
#include "camera_models/recent_answers.h"
#include "camera_models/unified_omni.h"

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <ceres/jet.h>

namespace colmap {

template <size_t N>
std::array<size_t, N> SphereModelIdxs(const std::array<int, N>& idxs) {
  std::array<size_t, N> out{};
  for (size_t i = 0; i < N; ++i) {
    out[i] = static_cast<size_t>(idxs[i]);
  }
  return out;
}

// COLMAP's static camera model interface for a camera_models/ struct: the
// functions. The static data members that models.cc defines for every model
// (through CAMERA_MODEL_CASES and SPHERA_CAMERA_MODEL_CASES) must belong to
// the model struct itself, so SPHERA_CAMERA_MODEL_MEMBERS declares them there.
template <typename SphereModel, typename CameraModel>
struct SphereCameraModelAdapter : public BaseSphericalCameraModel<CameraModel> {
  static constexpr size_t kNumParams = SphereModel::kNumParams;
  static constexpr size_t kNumFocalParams =
      SphereModel::kFocalLengthIdxs.size();
  static constexpr size_t kNumPrincipalPointParams =
      SphereModel::kPrincipalPointIdxs.size();
  static constexpr size_t kNumExtraParams =
      SphereModel::kExtraParamsIdxs.size();

  static inline CameraModelId InitializeModelId() {
    return static_cast<CameraModelId>(SphereModel::kModelId);
  }
  static inline std::string InitializeModelName() {
    return SphereModel::kModelName;
  }
  static inline std::string InitializeParamsInfo() {
    return SphereModel::kParamsInfo;
  }
  static inline std::array<size_t, kNumFocalParams>
  InitializeFocalLengthIdxs() {
    return SphereModelIdxs(SphereModel::kFocalLengthIdxs);
  }
  static inline std::array<size_t, kNumPrincipalPointParams>
  InitializePrincipalPointIdxs() {
    return SphereModelIdxs(SphereModel::kPrincipalPointIdxs);
  }
  static inline std::array<size_t, kNumExtraParams>
  InitializeExtraParamsIdxs() {
    return SphereModelIdxs(SphereModel::kExtraParamsIdxs);
  }
  static inline std::vector<double> InitializeParams(double focal_length,
                                                     size_t width,
                                                     size_t height) {
    return SphereModel::InitialParams(
        focal_length, static_cast<int>(width), static_cast<int>(height));
  }

  // Pixel of the point (u, v, w). With check_cheirality, false when the ray
  // is outside the model's field of view (which may reach behind the image
  // plane); without it, false only where the projection is not defined.
  template <typename T>
  static bool ImgFromCam(const T* params,
                         const T& u,
                         const T& v,
                         const T& w,
                         T* x,
                         T* y,
                         bool check_cheirality = true) {
    const T ray_in_cam[3] = {u, v, w};
    T pixel[2] = {T(0), T(0)};
    const bool visible =
        SphereModel::ImageFromRay(params, ray_in_cam, pixel);
    using std::isfinite;
    if (check_cheirality ? !visible
                         : !(isfinite(pixel[0]) && isfinite(pixel[1]))) {
      return false;
    }
    *x = pixel[0];
    *y = pixel[1];
    return true;
  }

  // ImgFromCam with d(x, y)/d(params) (2 x num_params) and d(x, y)/d(u, v, w)
  // (2 x 3), both row-major, from one forward-mode evaluation of the model.
  static bool ImgFromCamWithJac(const double* params,
                                const double& u,
                                const double& v,
                                const double& w,
                                double* x,
                                double* y,
                                double* J_params,
                                double* J_uvw,
                                bool check_cheirality = true) {
    constexpr int kN = static_cast<int>(kNumParams);
    using Jet = ceres::Jet<double, kN + 3>;
    Jet params_jet[kN];
    for (int i = 0; i < kN; ++i) {
      params_jet[i] = Jet(params[i], i);
    }
    const Jet u_jet(u, kN);
    const Jet v_jet(v, kN + 1);
    const Jet w_jet(w, kN + 2);
    Jet x_jet;
    Jet y_jet;
    if (!ImgFromCam(
            params_jet, u_jet, v_jet, w_jet, &x_jet, &y_jet, check_cheirality)) {
      return false;
    }
    *x = x_jet.a;
    *y = y_jet.a;
    if (J_params != nullptr) {
      for (int i = 0; i < kN; ++i) {
        J_params[i] = x_jet.v[i];
        J_params[kN + i] = y_jet.v[i];
      }
    }
    if (J_uvw != nullptr) {
      for (int i = 0; i < 3; ++i) {
        J_uvw[i] = x_jet.v[kN + i];
        J_uvw[3 + i] = y_jet.v[kN + i];
      }
    }
    return true;
  }

  // Normalized coordinates (u/w, v/w) of the pixel's ray; false when the ray
  // does not point in front of the image plane. CamRayFromImg covers the
  // whole field of view.
  static inline bool CamFromImg(
      const double* params, double x, double y, double* u, double* v) {
    double ray_in_cam[3];
    if (!CamRayFromImg(
            params, x, y, &ray_in_cam[0], &ray_in_cam[1], &ray_in_cam[2]) ||
        ray_in_cam[2] <= std::numeric_limits<double>::epsilon()) {
      return false;
    }
    *u = ray_in_cam[0] / ray_in_cam[2];
    *v = ray_in_cam[1] / ray_in_cam[2];
    return true;
  }

  // Unit bearing ray of a pixel anywhere in the model's image domain.
  static inline bool CamRayFromImg(const double* params,
                                   double x,
                                   double y,
                                   double* rx,
                                   double* ry,
                                   double* rz) {
    const double pixel[2] = {x, y};
    double ray_in_cam[3];
    if (!SphereModel::RayFromImage(params, pixel, ray_in_cam) ||
        !std::isfinite(ray_in_cam[0]) || !std::isfinite(ray_in_cam[1]) ||
        !std::isfinite(ray_in_cam[2])) {
      return false;
    }
    *rx = ray_in_cam[0];
    *ry = ray_in_cam[1];
    *rz = ray_in_cam[2];
    return true;
  }

  // Pixel thresholds become angles (radians) on the unit sphere, the unit of
  // COLMAP's ray-space estimators for spherical cameras.
  template <typename T>
  static inline T CamFromImgThreshold(const T* params, T threshold) {
    return threshold * T(SphereModel::PixelToAngle(params));
  }

  template <typename T>
  static inline bool HasBogusParams(const std::vector<T>& params,
                                    size_t width,
                                    size_t height,
                                    T /*min_focal_length_ratio*/,
                                    T /*max_focal_length_ratio*/,
                                    T /*max_extra_param*/) {
    // The check scans the lens's field; the mapper asks it for every
    // correspondence of the image it registers, with the same parameters.
    thread_local sphera::RecentAnswers<bool> answers;
    const double camera[3] = {static_cast<double>(SphereModel::kModelId),
                              static_cast<double>(width),
                              static_cast<double>(height)};
    return answers.Get(camera, 3, params.data(), params.size(), [&] {
      return !SphereModel::CheckParams(params,
                                       static_cast<int>(width),
                                       static_cast<int>(height))
                  .empty();
    });
  }

  // Focal length and principal point follow the image size; the shape
  // parameters (xi, alpha, beta, distortion) do not depend on it. A model
  // without a focal length rescales its own parameters.
  static inline void Rescale(double scale_x,
                             double scale_y,
                             std::vector<double>* params) {
    if constexpr (kNumFocalParams == 2) {
      (*params)[SphereModel::kFocalLengthIdxs[0]] *= scale_x;
      (*params)[SphereModel::kFocalLengthIdxs[1]] *= scale_y;
      (*params)[SphereModel::kPrincipalPointIdxs[0]] *= scale_x;
      (*params)[SphereModel::kPrincipalPointIdxs[1]] *= scale_y;
    } else {
      SphereModel::Rescale(scale_x, scale_y, params->data());
    }
  }
};

#define SPHERA_CAMERA_MODEL_MEMBERS(SphereModel)                              \
  using sphere_model = SphereModel;                                          \
  static constexpr size_t num_params = SphereModel::kNumParams;              \
  static constexpr size_t num_focal_params =                                 \
      SphereModel::kFocalLengthIdxs.size();                                   \
  static constexpr size_t num_pp_params =                                    \
      SphereModel::kPrincipalPointIdxs.size();                                \
  static constexpr size_t num_extra_params =                                 \
      SphereModel::kExtraParamsIdxs.size();                                   \
  static constexpr bool has_img_from_cam_with_jac = true;                    \
  static constexpr CameraModelId model_id =                                  \
      static_cast<CameraModelId>(SphereModel::kModelId);                      \
  static const std::string model_name;                                       \
  static const std::string params_info;                                      \
  static const std::array<size_t, num_focal_params> focal_length_idxs;       \
  static const std::array<size_t, num_pp_params> principal_point_idxs;       \
  static const std::array<size_t, num_extra_params> extra_params_idxs;

// Enhanced unified camera model (Khomutenko et al. 2016), id 16; replaces
// upstream's EUCMCameraModel, which stops at z > 0.
struct SphereEUCMCameraModel
    : public SphereCameraModelAdapter<sphera::EUCMModel,
                                      SphereEUCMCameraModel> {
  SPHERA_CAMERA_MODEL_MEMBERS(sphera::EUCMModel)
};

// Mei's unified omnidirectional model with radial-tangential distortion, id 64.
struct UnifiedOmniCameraModel
    : public SphereCameraModelAdapter<sphera::UnifiedOmniModel,
                                      UnifiedOmniCameraModel> {
  SPHERA_CAMERA_MODEL_MEMBERS(sphera::UnifiedOmniModel)
};

// Double sphere model (Usenko et al. 2018), id 65.
struct DoubleSphereCameraModel
    : public SphereCameraModelAdapter<sphera::DoubleSphereModel,
                                      DoubleSphereCameraModel> {
  SPHERA_CAMERA_MODEL_MEMBERS(sphera::DoubleSphereModel)
};

// Kannala-Brandt (OpenCV's fisheye model), id 5; replaces upstream's
// OpenCVFisheyeCameraModel, which stops at z > 0.
struct SphereOpenCVFisheyeCameraModel
    : public SphereCameraModelAdapter<sphera::OpenCVFisheyeModel,
                                      SphereOpenCVFisheyeCameraModel> {
  SPHERA_CAMERA_MODEL_MEMBERS(sphera::OpenCVFisheyeModel)
};

// Kannala-Brandt with tangential and thin-prism terms, id 10; replaces
// upstream's ThinPrismFisheyeCameraModel, which stops at z > 0.
struct SphereThinPrismFisheyeCameraModel
    : public SphereCameraModelAdapter<sphera::ThinPrismFisheyeModel,
                                      SphereThinPrismFisheyeCameraModel> {
  SPHERA_CAMERA_MODEL_MEMBERS(sphera::ThinPrismFisheyeModel)
};

// Scaramuzza's OCamCalib model, id 66.
struct OCamCameraModel
    : public SphereCameraModelAdapter<sphera::OCamModel, OCamCameraModel> {
  SPHERA_CAMERA_MODEL_MEMBERS(sphera::OCamModel)
};

#define SPHERA_CAMERA_MODEL_CASES                     \
  CAMERA_MODEL_CASE(SphereOpenCVFisheyeCameraModel)    \
  CAMERA_MODEL_CASE(SphereThinPrismFisheyeCameraModel) \
  CAMERA_MODEL_CASE(SphereEUCMCameraModel)             \
  CAMERA_MODEL_CASE(UnifiedOmniCameraModel)            \
  CAMERA_MODEL_CASE(DoubleSphereCameraModel)           \
  CAMERA_MODEL_CASE(OCamCameraModel)

}  // namespace colmap
