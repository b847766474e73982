// Conversion of a lens projection into one of the camera models of
// camera_models/registry.h, by least squares over rays of the lens's field.
//
// Problem
// -------
// The source lens is given by samples (ray_in_cam_i, pixel_i): the pixel at
// which the lens images the unit ray. The target model's parameters p
// minimise
//   sum_i |ImageFromRay(p, ray_in_cam_i) - pixel_i|²      [pixels²]
// (no robust loss: every sample is exact, so the largest error matters as
// much as the typical one, and both are reported). The error is in pixels
// because that is what a user compares with feature noise.
//
// Samples
// -------
// Samples cover what the source images inside the image frame: its image
// circle as far as the frame crops it, and no further than the projection is
// monotone. Along each of a set of meridians (azimuths), the walk goes out
// from the optical axis in small steps of angle (projection samplers) or of
// pixel radius (unprojection samplers) and stops at the first step that is
// not visible, leaves the image, or folds (the distance from the axis's
// pixel, resp. the angle from the axis, stops growing).
//
// Fit
// ---
// The start is the target's InitialParams with the source's principal point
// (the pixel of the optical axis) and the source's focal length on the axis
// (pixel radius per radian of the first samples), scaled so that the target's
// PixelToAngle near the axis matches the source's. The field is then opened
// in stages (the samples up to 30°, 60°, ... from the axis, each stage started
// from the last one's result), so that a target whose start sees no ray
// beyond 90° (a pinhole start, OCAM's) grows into a wide field. A stage uses
// the samples its start sees (a stage with the same samples as the last is
// skipped); the final errors are over all samples, those the fitted model
// does not see counted apart.
//
// No COLMAP headers: Eigen, Ceres and camera_models/ only.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace sphera {

// A unit ray in the camera frame (x right, y down, z forward) and its pixel in
// COLMAP's convention (the centre of the upper-left pixel is (0.5, 0.5)).
struct RayPixelSample {
  Eigen::Vector3d ray_in_cam = Eigen::Vector3d::UnitZ();
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
};

// A lens's projection: false when the ray is not visible.
using ImageFromRayFunction =
    std::function<bool(const Eigen::Vector3d& ray_in_cam,
                       Eigen::Vector2d* pixel)>;
// A lens's unprojection: false when the pixel is outside its domain. The
// returned ray need not be normalised.
using RayFromImageFunction = std::function<bool(const Eigen::Vector2d& pixel,
                                                Eigen::Vector3d* ray_in_cam)>;

struct LensSamplingOptions {
  int num_meridians = 48;
  // Walk step and the spacing of the kept samples, in degrees (projection)
  // and pixels (unprojection).
  double step_deg = 0.25;
  double sample_spacing_deg = 2.0;
  double step_px = 0.5;
  double sample_spacing_px = 12.0;
  // Rays further from the optical axis are not sampled (degrees): a
  // circular fisheye's half field, so that a fit describes the lens where it
  // images and not the frame's corners beyond its image circle.
  double max_angle_deg = 180;
};

// Samples of the lens by projection: the optical axis must be visible.
std::vector<RayPixelSample> SampleLensByProjection(
    const ImageFromRayFunction& image_from_ray, int width, int height,
    const LensSamplingOptions& options = LensSamplingOptions());

// Samples of the lens by unprojection, walking out from principal_pixel (the
// pixel of the optical axis).
std::vector<RayPixelSample> SampleLensByUnprojection(
    const RayFromImageFunction& ray_from_image,
    const Eigen::Vector2d& principal_pixel, int width, int height,
    const LensSamplingOptions& options = LensSamplingOptions());

// The errors of a model against samples.
struct ModelFitErrors {
  int num_samples = 0;
  double max_angle_deg = 0;  // the widest sample ray from the optical axis
  double median_error_px = 0;
  double max_error_px = 0;    // over the samples the model sees
  int num_not_visible = 0;    // samples the model does not see
};

struct ModelConversion {
  int model_id = -1;
  std::string model_name;
  std::vector<double> params;
  ModelFitErrors errors;
  // CheckParams' message for the fitted params (empty: accepted).
  std::string check_message;
};

// Fits the model with the given id to the samples of a width x height image.
// Throws std::invalid_argument for an unknown id, a model that cannot be
// fitted (EQUIRECTANGULAR, whose parameters are the image size) or fewer
// samples than parameters.
ModelConversion FitModelToSamples(int model_id,
                                  const std::vector<RayPixelSample>& samples,
                                  int width, int height);

// The model of ours that describes the samples best: each of the candidates
// fitted, the one that sees every sample, passes CheckParams and has the
// smallest largest error (else the smallest median error). Candidates:
// OPENCV_FISHEYE, UNIFIED_OMNI, DOUBLE_SPHERE, EUCM, and OPENCV when every
// sample is within 80° of the axis.
ModelConversion FitNearestModel(const std::vector<RayPixelSample>& samples,
                                int width, int height);

// The errors of params of the model against the samples.
ModelFitErrors ModelErrors(int model_id, const std::vector<double>& params,
                           const std::vector<RayPixelSample>& samples);

}  // namespace sphera
