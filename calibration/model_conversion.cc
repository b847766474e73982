#include "calibration/model_conversion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <ceres/ceres.h>

#include "camera_models/registry.h"

namespace sphera {
namespace {

constexpr double kDegree = internal::kPi / 180.0;

bool InsideImage(const Eigen::Vector2d& pixel, int width, int height) {
  return pixel.allFinite() && pixel.x() >= 0 && pixel.x() <= width &&
         pixel.y() >= 0 && pixel.y() <= height;
}

double AngleFromAxis(const Eigen::Vector3d& ray_in_cam) {
  return std::atan2(ray_in_cam.head<2>().norm(), ray_in_cam.z());
}

// Pixel error of the target model at one sample; false when the model does
// not see the ray (the solver then shortens its step).
template <typename Model>
struct SampleReprojectionError {
  RayPixelSample sample;

  template <typename T>
  bool operator()(const T* params, T* residual) const {
    const T ray[3] = {T(sample.ray_in_cam.x()), T(sample.ray_in_cam.y()),
                      T(sample.ray_in_cam.z())};
    T pixel[2];
    if (!Model::ImageFromRay(params, ray, pixel)) return false;
    residual[0] = pixel[0] - T(sample.pixel.x());
    residual[1] = pixel[1] - T(sample.pixel.y());
    return true;
  }

  static ceres::CostFunction* Create(const RayPixelSample& sample) {
    return new ceres::AutoDiffCostFunction<SampleReprojectionError, 2,
                                           Model::kNumParams>(
        new SampleReprojectionError{sample});
  }
};

template <typename Model>
void SolveStage(const std::vector<const RayPixelSample*>& samples,
                std::vector<double>* params) {
  ceres::Problem problem;
  for (const RayPixelSample* sample : samples) {
    problem.AddResidualBlock(
        SampleReprojectionError<Model>::Create(*sample), nullptr,
        params->data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 100;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  options.gradient_tolerance = 1e-14;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
}

// The pixel of the optical axis and the focal length there (pixels per
// radian), from the samples nearest the axis.
void AxisOfSamples(const std::vector<RayPixelSample>& samples,
                   Eigen::Vector2d* principal_pixel, double* focal_length) {
  const auto axis = std::min_element(
      samples.begin(), samples.end(),
      [](const RayPixelSample& a, const RayPixelSample& b) {
        return AngleFromAxis(a.ray_in_cam) < AngleFromAxis(b.ray_in_cam);
      });
  *principal_pixel = axis->pixel;
  std::vector<double> focal_lengths;
  double nearest = std::numeric_limits<double>::infinity();
  for (const RayPixelSample& sample : samples) {
    const double angle = AngleFromAxis(sample.ray_in_cam);
    if (angle > 1e-9) nearest = std::min(nearest, angle);
  }
  for (const RayPixelSample& sample : samples) {
    const double angle = AngleFromAxis(sample.ray_in_cam);
    if (angle > 1e-9 && angle <= 1.5 * nearest) {
      focal_lengths.push_back((sample.pixel - *principal_pixel).norm() /
                              angle);
    }
  }
  if (focal_lengths.empty()) {
    *focal_length = 0;
    return;
  }
  std::nth_element(focal_lengths.begin(),
                   focal_lengths.begin() + focal_lengths.size() / 2,
                   focal_lengths.end());
  *focal_length = focal_lengths[focal_lengths.size() / 2];
}

template <typename Model>
std::vector<double> FitModel(const std::vector<RayPixelSample>& samples,
                             int width, int height) {
  Eigen::Vector2d principal_pixel;
  double focal_length;
  AxisOfSamples(samples, &principal_pixel, &focal_length);
  if (!(focal_length > 0)) {
    throw std::invalid_argument(
        "the samples give no focal length near the optical axis");
  }
  // InitialParams' focal parameter scaled so that the start has the source's
  // radians per pixel on the axis (e.g. UNIFIED_OMNI's start, xi = 1, sees
  // fx / 2 pixels per radian there).
  std::vector<double> params =
      Model::InitialParams(focal_length, width, height);
  const double start_focal =
      focal_length * focal_length * Model::PixelToAngle(params.data());
  params = Model::InitialParams(start_focal, width, height);
  params[Model::kPrincipalPointIdxs[0]] = principal_pixel.x();
  params[Model::kPrincipalPointIdxs[1]] = principal_pixel.y();

  std::vector<const RayPixelSample*> last_stage;
  for (const double limit_deg : {30.0, 60.0, 90.0, 120.0, 150.0, 180.0}) {
    std::vector<const RayPixelSample*> stage;
    for (const RayPixelSample& sample : samples) {
      Eigen::Vector2d pixel;
      if (AngleFromAxis(sample.ray_in_cam) <= limit_deg * kDegree + 1e-9 &&
          Model::ImageFromRay(params.data(), sample.ray_in_cam.data(),
                              pixel.data()) &&
          pixel.allFinite()) {
        stage.push_back(&sample);
      }
    }
    if (stage.size() >= static_cast<size_t>(Model::kNumParams) &&
        stage != last_stage) {
      SolveStage<Model>(stage, &params);
    }
    last_stage = std::move(stage);
  }
  return params;
}

}  // namespace

std::vector<RayPixelSample> SampleLensByProjection(
    const ImageFromRayFunction& image_from_ray, int width, int height,
    const LensSamplingOptions& options) {
  std::vector<RayPixelSample> samples;
  Eigen::Vector2d axis_pixel;
  if (!image_from_ray(Eigen::Vector3d::UnitZ(), &axis_pixel) ||
      !InsideImage(axis_pixel, width, height)) {
    return samples;
  }
  samples.push_back({Eigen::Vector3d::UnitZ(), axis_pixel});
  const int keep_every = std::max(
      1, static_cast<int>(std::lround(options.sample_spacing_deg /
                                      options.step_deg)));
  for (int m = 0; m < options.num_meridians; ++m) {
    const double azimuth = 2 * internal::kPi * m / options.num_meridians;
    double last_distance = 0;
    for (int step = 1;; ++step) {
      const double angle = step * options.step_deg * kDegree;
      if (angle >= internal::kPi || angle > options.max_angle_deg * kDegree) {
        break;
      }
      const Eigen::Vector3d ray(std::sin(angle) * std::cos(azimuth),
                                std::sin(angle) * std::sin(azimuth),
                                std::cos(angle));
      Eigen::Vector2d pixel;
      if (!image_from_ray(ray, &pixel) || !InsideImage(pixel, width, height)) {
        break;
      }
      const double distance = (pixel - axis_pixel).norm();
      if (!(distance > last_distance)) break;  // folds
      last_distance = distance;
      if (step % keep_every == 0) samples.push_back({ray, pixel});
    }
  }
  return samples;
}

std::vector<RayPixelSample> SampleLensByUnprojection(
    const RayFromImageFunction& ray_from_image,
    const Eigen::Vector2d& principal_pixel, int width, int height,
    const LensSamplingOptions& options) {
  std::vector<RayPixelSample> samples;
  Eigen::Vector3d axis_ray;
  if (!InsideImage(principal_pixel, width, height) ||
      !ray_from_image(principal_pixel, &axis_ray) || !axis_ray.allFinite() ||
      !(axis_ray.norm() > 0)) {
    return samples;
  }
  samples.push_back({axis_ray.normalized(), principal_pixel});
  const int keep_every = std::max(
      1, static_cast<int>(std::lround(options.sample_spacing_px /
                                      options.step_px)));
  for (int m = 0; m < options.num_meridians; ++m) {
    const double azimuth = 2 * internal::kPi * m / options.num_meridians;
    const Eigen::Vector2d direction(std::cos(azimuth), std::sin(azimuth));
    double last_angle = 0;
    for (int step = 1;; ++step) {
      const Eigen::Vector2d pixel =
          principal_pixel + step * options.step_px * direction;
      Eigen::Vector3d ray;
      if (!InsideImage(pixel, width, height) || !ray_from_image(pixel, &ray) ||
          !ray.allFinite() || !(ray.norm() > 0)) {
        break;
      }
      ray.normalize();
      const double angle =
          std::atan2(ray.cross(samples.front().ray_in_cam).norm(),
                     ray.dot(samples.front().ray_in_cam));
      if (!(angle > last_angle)) break;  // folds
      if (angle > options.max_angle_deg * kDegree) break;
      last_angle = angle;
      if (step % keep_every == 0) samples.push_back({ray, pixel});
    }
  }
  return samples;
}

ModelFitErrors ModelErrors(int model_id, const std::vector<double>& params,
                           const std::vector<RayPixelSample>& samples) {
  ModelFitErrors errors;
  errors.num_samples = static_cast<int>(samples.size());
  std::vector<double> pixel_errors;
  for (const RayPixelSample& sample : samples) {
    errors.max_angle_deg = std::max(errors.max_angle_deg,
                                    AngleFromAxis(sample.ray_in_cam) / kDegree);
    Eigen::Vector2d pixel;
    if (!ImageFromRay(model_id, params, sample.ray_in_cam, &pixel) ||
        !pixel.allFinite()) {
      ++errors.num_not_visible;
      continue;
    }
    pixel_errors.push_back((pixel - sample.pixel).norm());
  }
  if (!pixel_errors.empty()) {
    std::sort(pixel_errors.begin(), pixel_errors.end());
    const size_t n = pixel_errors.size();
    errors.median_error_px =
        n % 2 ? pixel_errors[n / 2]
              : 0.5 * (pixel_errors[n / 2 - 1] + pixel_errors[n / 2]);
    errors.max_error_px = pixel_errors.back();
  }
  return errors;
}

ModelConversion FitModelToSamples(int model_id,
                                  const std::vector<RayPixelSample>& samples,
                                  int width, int height) {
  if (model_id == static_cast<int>(ModelId::kEquirectangular)) {
    throw std::invalid_argument(
        "EQUIRECTANGULAR cannot be fitted to a lens: its parameters are the "
        "image size");
  }
  ModelConversion conversion;
  conversion.model_id = model_id;
  conversion.params = internal::VisitModel(model_id, [&](auto model) {
    using Model = decltype(model);
    conversion.model_name = Model::kModelName;
    if (samples.size() < static_cast<size_t>(Model::kNumParams)) {
      throw std::invalid_argument(
          "too few rays of the lens inside the image (" +
          std::to_string(samples.size()) + ") to fit " + Model::kModelName);
    }
    return FitModel<Model>(samples, width, height);
  });
  conversion.errors = ModelErrors(model_id, conversion.params, samples);
  conversion.check_message =
      CheckParams(model_id, conversion.params, width, height);
  return conversion;
}

ModelConversion FitNearestModel(const std::vector<RayPixelSample>& samples,
                                int width, int height) {
  std::vector<ModelId> candidates = {ModelId::kOpenCVFisheye,
                                     ModelId::kUnifiedOmni,
                                     ModelId::kDoubleSphere, ModelId::kEUCM};
  double max_angle_deg = 0;
  for (const RayPixelSample& sample : samples) {
    max_angle_deg =
        std::max(max_angle_deg, AngleFromAxis(sample.ray_in_cam) / kDegree);
  }
  if (max_angle_deg < 80) candidates.push_back(ModelId::kOpenCV);
  ModelConversion best;
  bool best_complete = false;
  for (const ModelId id : candidates) {
    ModelConversion conversion =
        FitModelToSamples(static_cast<int>(id), samples, width, height);
    const bool complete = conversion.errors.num_not_visible == 0 &&
                          conversion.check_message.empty();
    const bool better =
        best.model_id < 0 || (complete && !best_complete) ||
        (complete == best_complete &&
         (complete ? conversion.errors.max_error_px < best.errors.max_error_px
                   : conversion.errors.median_error_px <
                         best.errors.median_error_px));
    if (better) {
      best = std::move(conversion);
      best_complete = complete;
    }
  }
  return best;
}

}  // namespace sphera
