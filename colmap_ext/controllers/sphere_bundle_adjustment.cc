#include "colmap_ext/controllers/sphere_bundle_adjustment.h"

#include "colmap/estimators/bundle_adjustment.h"
#include "colmap/estimators/bundle_adjustment_ceres.h"
#include "colmap/estimators/cost_functions/manifold.h"
#include "colmap/estimators/cost_functions/reprojection_error.h"
#include "colmap/estimators/cost_functions/utils.h"
#include "colmap/sensor/models.h"
#include "colmap/util/logging.h"
#include "colmap_ext/estimators/sphere_cost_functions.h"
#include "colmap_ext/scene/camera_params_error.h"

#include "camera_models/registry.h"
#include "estimators/angular_residual.h"
#include "estimators/camera_only_bundle_adjustment.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include <ceres/ceres.h>

namespace colmap {
namespace {

using Options = SphereBundleAdjustmentOptions;

////////////////////////////////////////////////////////////////////////////////
// Option values
////////////////////////////////////////////////////////////////////////////////

// Empty string, or the message for --`option` holding a value outside its
// enum (a caller that set the field from an integer).
template <typename E>
std::string CheckEnum(const std::string& option,
                      const E value,
                      std::string_view (*to_string)(E)) {
  try {
    to_string(value);
    return "";
  } catch (const std::runtime_error&) {
    return "--" + option + ": " + std::to_string(static_cast<int>(value)) +
           " is none of its values";
  }
}

////////////////////////////////////////////////////////////////////////////////
// Helpers
////////////////////////////////////////////////////////////////////////////////

double Seconds(const std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                       start)
      .count();
}

// Radians per pixel of a camera: the one conversion between pixels and
// angles (tau, the Cauchy scale of the camera-only BA, pixel equivalents of
// angular errors and of the angular residual). Spherical models: the model's
// own scale (2 pi / W for EQUIRECTANGULAR, about 1 / focal at the centre for
// SPHERA's spherical fisheye models); perspective models: 1 / focal, the angle
// of one pixel at the image centre.
double RadiansPerPixel(const Camera& camera) {
  return camera.CamFromImgThreshold(1.0);
}

std::vector<image_t> SortedRegImageIds(const Reconstruction& reconstruction) {
  std::vector<image_t> ids = reconstruction.RegImageIds();
  std::sort(ids.begin(), ids.end());
  return ids;
}

// The camera's parameters are checked by CameraParamsError
// (colmap_ext/scene/camera_params_error.h): wrong count, not finite,
// non-positive focal length, and the models' own checks (camera_models/,
// e.g. EQUIRECTANGULAR w = 2 h = the image size).

size_t NumImagesInFrame(const Frame& frame) {
  size_t num_images = 0;
  for (const data_t& data_id : frame.ImageIds()) {
    (void)data_id;
    ++num_images;
  }
  return num_images;
}

// Checks shared by both modes: >= 2 registered images, every registered
// image with enough observations of points with >= 2 observations, one image
// per frame for CAMERA_ONLY, and the two gauge images (the first registered
// image and the next one in another frame) not at the same centre.
bool CheckModel(const Options& options,
                const Reconstruction& reconstruction,
                image_t* gauge_image1,
                image_t* gauge_image2,
                std::string* error) {
  const std::vector<image_t> ids = SortedRegImageIds(reconstruction);
  if (ids.size() < 2) {
    *error = "the model has " + std::to_string(ids.size()) +
             " registered images; bundle adjustment needs at least 2";
    return false;
  }
  if (reconstruction.NumPoints3D() == 0) {
    *error = "the model has no 3D points (observations)";
    return false;
  }
  std::map<image_t, int> counts;
  for (const auto& [point3D_id, point3D] : reconstruction.Points3D()) {
    if (point3D.track.Length() < 2) continue;
    for (const TrackElement& el : point3D.track.Elements()) {
      ++counts[el.image_id];
    }
  }
  for (const image_t id : ids) {
    if (counts[id] < options.min_observations_per_image) {
      *error = "too few observations: image " +
               reconstruction.Image(id).Name() + " observes " +
               std::to_string(counts[id]) +
               " points of tracks with >= 2 observations "
               "(--min_observations_per_image " +
               std::to_string(options.min_observations_per_image) + ")";
      return false;
    }
  }
  if (options.mode == Options::Mode::CAMERA_ONLY) {
    for (const frame_t frame_id : reconstruction.RegFrameIds()) {
      const size_t num_images =
          NumImagesInFrame(reconstruction.Frame(frame_id));
      if (num_images != 1) {
        *error = "--mode camera_only refines one pose per image, but frame " +
                 std::to_string(frame_id) + " holds " +
                 std::to_string(num_images) +
                 " images (a camera rig); use --mode full";
        return false;
      }
    }
  }
  *gauge_image1 = ids[0];
  *gauge_image2 = kInvalidImageId;
  const frame_t frame1 = reconstruction.Image(ids[0]).FrameId();
  for (size_t i = 1; i < ids.size(); ++i) {
    if (reconstruction.Image(ids[i]).FrameId() != frame1) {
      *gauge_image2 = ids[i];
      break;
    }
  }
  if (*gauge_image2 == kInvalidImageId) {
    *error =
        "degenerate geometry: all registered images belong to one frame, the "
        "scale gauge cannot be fixed";
    return false;
  }
  const Image& image1 = reconstruction.Image(*gauge_image1);
  const Image& image2 = reconstruction.Image(*gauge_image2);
  const double baseline =
      (image1.ProjectionCenter() - image2.ProjectionCenter()).norm();
  if (!(baseline > 1e-12)) {
    *error = "degenerate geometry: the first two images " + image1.Name() +
             " and " + image2.Name() +
             " share their centre, the scale gauge cannot be fixed";
    return false;
  }
  return true;
}

////////////////////////////////////////////////////////////////////////////////
// Residual of one observation
////////////////////////////////////////////////////////////////////////////////

// The residual of one observation in the intrinsics step of the camera-only
// mode, with the parameter blocks point3D (3), cam_from_world (7) and camera
// params: for a spherical camera the angular residual of bundle adjustment
// (colmap_ext/estimators/sphere_cost_functions.h), for a perspective
// one COLMAP's pixel reprojection error.
ceres::CostFunction* CreateObservationCost(const Camera& camera,
                                           const Eigen::Vector2d& point2D) {
  return CreateSphereCameraCostFunction<ReprojErrorCostFunctor>(
      SphereResidualType::ANGULAR, camera, point2D);
}

// Indices of the camera parameters held constant: all without refinement,
// else the metadata parameters (EQUIRECTANGULAR w, h) and the principal point.
std::vector<int> HeldCameraParams(const Camera& camera, const bool refine) {
  std::vector<int> idxs;
  if (!refine) {
    for (size_t i = 0; i < camera.params.size(); ++i) {
      idxs.push_back(static_cast<int>(i));
    }
    return idxs;
  }
  for (const size_t idx : camera.MetaDataParamsIdxs()) {
    idxs.push_back(static_cast<int>(idx));
  }
  for (const size_t idx : camera.PrincipalPointIdxs()) {
    idxs.push_back(static_cast<int>(idx));
  }
  std::sort(idxs.begin(), idxs.end());
  idxs.erase(std::unique(idxs.begin(), idxs.end()), idxs.end());
  return idxs;
}

void ParameterizeCamera(ceres::Problem* problem,
                        Camera* camera,
                        const bool refine) {
  if (!problem->HasParameterBlock(camera->params.data())) return;
  const std::vector<int> held = HeldCameraParams(*camera, refine);
  if (held.size() == camera->params.size()) {
    problem->SetParameterBlockConstant(camera->params.data());
  } else if (!held.empty()) {
    SetManifold(problem,
                camera->params.data(),
                CreateSubsetManifold(static_cast<int>(camera->params.size()),
                                     held));
  }
}

void SetPoseManifold(ceres::Problem* problem, Rigid3d* pose) {
  SetManifold(problem,
              pose->params.data(),
              CreateProductManifold(CreateEigenQuaternionManifold(),
                                    CreateEuclideanManifold<3>()));
}

void SetCeresOptions(const Options& options,
                     CeresBundleAdjustmentOptions* ceres_options) {
  ceres_options->solver_options.max_num_iterations =
      std::max(100, options.max_iterations);
  ceres_options->solver_options.function_tolerance = 1e-12;
  ceres_options->solver_options.num_threads = 1;
  if (options.loss == Options::Loss::CAUCHY) {
    ceres_options->loss_function_type =
        CeresBundleAdjustmentOptions::LossFunctionType::CAUCHY;
    ceres_options->loss_function_scale = options.loss_scale_px;
  }
}

////////////////////////////////////////////////////////////////////////////////
// The three adjustments; each works on the reconstruction it is given.
////////////////////////////////////////////////////////////////////////////////

// FULL: COLMAP's bundle adjuster, with the angular or the pixel residual for
// the spherical cameras.
bool RunFull(const Options& options,
             const image_t gauge_image1,
             Reconstruction* reconstruction,
             int* iterations,
             std::string* error) {
  BundleAdjustmentOptions ba_options;
  ba_options.backend = BundleAdjustmentBackend::CERES;
  ba_options.sphere_residual = options.residual;
  ba_options.refine_focal_length = options.refine_intrinsics;
  ba_options.refine_extra_params = options.refine_intrinsics;
  ba_options.refine_principal_point = false;
  ba_options.refine_sensor_from_rig = false;
  ba_options.print_summary = false;
  SetCeresOptions(options, ba_options.ceres.get());

  BundleAdjustmentConfig config;
  for (const image_t image_id : SortedRegImageIds(*reconstruction)) {
    config.AddImage(image_id);
  }
  for (const auto& [point3D_id, point3D] : reconstruction->Points3D()) {
    if (point3D.track.Length() < 2) config.IgnorePoint(point3D_id);
  }
  config.SetConstantRigFromWorldPose(
      reconstruction->Image(gauge_image1).FrameId());
  config.FixGauge(BundleAdjustmentGauge::TWO_CAMS_FROM_WORLD);

  const std::unique_ptr<BundleAdjuster> adjuster =
      CreateDefaultBundleAdjuster(ba_options, config, *reconstruction);
  const std::shared_ptr<BundleAdjustmentSummary> summary = adjuster->Solve();
  if (summary == nullptr || !summary->IsSolutionUsable()) {
    *error = "bundle adjustment failed" +
             (summary == nullptr ? std::string()
                                 : ": " + summary->BriefReport());
    return false;
  }
  const auto ceres_summary =
      std::dynamic_pointer_cast<CeresBundleAdjustmentSummary>(summary);
  *iterations = ceres_summary == nullptr
                    ? 0
                    : static_cast<int>(
                          ceres_summary->ceres_summary.iterations.size());
  return true;
}

// CAMERA_ONLY: sphera::CameraOnlyBundleAdjustment.
bool RunCameraOnly(const Options& options,
                   Reconstruction* reconstruction,
                   int* iterations,
                   std::string* error) {
  const std::vector<image_t> ids = SortedRegImageIds(*reconstruction);
  std::unordered_map<image_t, int> image_idx;
  sphera::CameraOnlyBAProblem problem;
  for (size_t i = 0; i < ids.size(); ++i) {
    image_idx[ids[i]] = static_cast<int>(i);
    const Rigid3d cam_from_world = reconstruction->Image(ids[i]).CamFromWorld();
    sphera::CameraPose pose;
    pose.rotation = Eigen::Quaterniond(cam_from_world.rotation());
    pose.translation = cam_from_world.translation();
    problem.poses.push_back(pose);
  }
  // Tracks in point id order; elements parallel to the rays.
  std::vector<point3D_t> point3D_ids;
  for (const auto& [point3D_id, point3D] : reconstruction->Points3D()) {
    point3D_ids.push_back(point3D_id);
  }
  std::sort(point3D_ids.begin(), point3D_ids.end());
  std::vector<std::vector<TrackElement>> elements;
  size_t num_unliftable = 0;
  for (const point3D_t point3D_id : point3D_ids) {
    const Point3D& point3D = reconstruction->Point3D(point3D_id);
    sphera::RayTrack track;
    std::vector<TrackElement> els;
    for (const TrackElement& el : point3D.track.Elements()) {
      const auto it = image_idx.find(el.image_id);
      if (it == image_idx.end()) continue;
      const Image& image = reconstruction->Image(el.image_id);
      const Camera& camera = reconstruction->Camera(image.CameraId());
      const std::optional<Eigen::Vector3d> ray =
          camera.CamRayFromImg(image.Point2D(el.point2D_idx).xy);
      if (!ray.has_value()) {
        ++num_unliftable;
        continue;
      }
      sphera::RayObservation obs;
      obs.image_idx = it->second;
      obs.ray = *ray;
      track.push_back(obs);
      els.push_back(el);
    }
    problem.tracks.push_back(track);
    elements.push_back(els);
  }
  if (num_unliftable > 0) {
    LOG(WARNING) << num_unliftable
                 << " observations outside their camera's image domain were "
                    "ignored";
  }

  // Working copy of the cameras: the intrinsics step changes them, and the
  // reconstruction is modified only on success.
  std::unordered_map<camera_t, Camera> cameras;
  for (const auto& [camera_id, camera] : reconstruction->Cameras()) {
    cameras[camera_id] = camera;
  }
  std::vector<camera_t> camera_of_image(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) {
    camera_of_image[i] = reconstruction->Image(ids[i]).CameraId();
  }

  sphera::CameraOnlyBAOptions ba;
  ba.tau_rad_fn = [&](const int i) {
    return options.tau_px * RadiansPerPixel(cameras.at(camera_of_image[i]));
  };
  ba.max_iterations = options.max_iterations;
  ba.min_observations_per_image = options.min_observations_per_image;
  if (options.loss == Options::Loss::CAUCHY) {
    double sum = 0;
    for (const auto& [camera_id, camera] : cameras) {
      sum += options.loss_scale_px * RadiansPerPixel(camera);
    }
    ba.loss = sphera::CameraOnlyBALoss::kCauchy;
    ba.loss_scale_rad = sum / std::max<size_t>(1, cameras.size());
  }
  ba.gauge_image0 = 0;
  ba.gauge_image1 = 1;

  if (options.refine_intrinsics) {
    // Intrinsics of the cameras with focal parameters, together with the
    // poses of their images (focal length and pose are coupled; the two gauge
    // images stay fixed), on the fixed reliable points.
    ba.intrinsics_step = [&](std::vector<sphera::CameraPose>* poses,
                             const std::vector<sphera::ReliablePoint>& points,
                             std::vector<sphera::RayTrack>* tracks) {
      std::vector<Rigid3d> cams_from_world(poses->size());
      for (size_t i = 0; i < poses->size(); ++i) {
        cams_from_world[i] =
            Rigid3d((*poses)[i].rotation, (*poses)[i].translation);
      }
      std::vector<Eigen::Vector3d> xyzs(points.size());
      std::unique_ptr<ceres::LossFunction> loss;
      if (options.loss == Options::Loss::CAUCHY) {
        loss = std::make_unique<ceres::CauchyLoss>(options.loss_scale_px);
      }
      ceres::Problem::Options problem_options;
      problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
      ceres::Problem intrinsics_problem(problem_options);
      for (size_t p = 0; p < points.size(); ++p) {
        const sphera::ReliablePoint& point = points[p];
        xyzs[p] = point.xyz;
        const std::vector<TrackElement>& els = elements[point.track_idx];
        const sphera::RayTrack& track = (*tracks)[point.track_idx];
        for (size_t k = 0; k < track.size(); ++k) {
          const int i = track[k].image_idx;
          Camera& camera = cameras.at(camera_of_image[i]);
          if (camera.FocalLengthIdxs().size() == 0) continue;
          const Eigen::Vector2d& xy =
              reconstruction->Image(ids[i]).Point2D(els[k].point2D_idx).xy;
          if (!camera.CamRayFromImg(xy).has_value()) continue;
          ceres::CostFunction* cost = CreateObservationCost(camera, xy);
          intrinsics_problem.AddResidualBlock(cost,
                                              loss.get(),
                                              xyzs[p].data(),
                                              cams_from_world[i].params.data(),
                                              camera.params.data());
          intrinsics_problem.SetParameterBlockConstant(xyzs[p].data());
        }
      }
      if (intrinsics_problem.NumResidualBlocks() == 0) return true;
      for (size_t i = 0; i < poses->size(); ++i) {
        double* params = cams_from_world[i].params.data();
        if (!intrinsics_problem.HasParameterBlock(params)) continue;
        if (static_cast<int>(i) == ba.gauge_image0 ||
            static_cast<int>(i) == ba.gauge_image1) {
          intrinsics_problem.SetParameterBlockConstant(params);
        } else {
          SetPoseManifold(&intrinsics_problem, &cams_from_world[i]);
        }
      }
      for (auto& [camera_id, camera] : cameras) {
        ParameterizeCamera(&intrinsics_problem, &camera, /*refine=*/true);
      }
      ceres::Solver::Options solver_options;
      solver_options.linear_solver_type = ceres::DENSE_QR;
      solver_options.max_num_iterations = 50;
      solver_options.num_threads = 1;
      solver_options.logging_type = ceres::SILENT;
      ceres::Solver::Summary summary;
      ceres::Solve(solver_options, &intrinsics_problem, &summary);
      if (!summary.IsSolutionUsable()) return false;
      for (size_t i = 0; i < poses->size(); ++i) {
        (*poses)[i].rotation =
            Eigen::Quaterniond(cams_from_world[i].rotation()).normalized();
        (*poses)[i].translation = cams_from_world[i].translation();
      }
      // Re-lift the rays of every observation (the intrinsics changed).
      for (size_t j = 0; j < tracks->size(); ++j) {
        for (size_t k = 0; k < (*tracks)[j].size(); ++k) {
          sphera::RayObservation& obs = (*tracks)[j][k];
          const Camera& camera = cameras.at(camera_of_image[obs.image_idx]);
          const Eigen::Vector2d& xy = reconstruction->Image(ids[obs.image_idx])
                                          .Point2D(elements[j][k].point2D_idx)
                                          .xy;
          const std::optional<Eigen::Vector3d> ray = camera.CamRayFromImg(xy);
          if (!ray.has_value()) return false;
          obs.ray = *ray;
        }
      }
      return true;
    };
  }

  const sphera::CameraOnlyBAResult result =
      sphera::CameraOnlyBundleAdjustment(problem, ba);
  if (!result.Success()) {
    std::ostringstream message;
    message << "camera-only BA failed ("
            << sphera::CameraOnlyBAStatusName(result.status)
            << "): ";
    if (result.image_idx >= 0 &&
        result.image_idx < static_cast<int>(ids.size())) {
      message << "image " << reconstruction->Image(ids[result.image_idx]).Name()
              << " ";
    }
    message << result.message;
    if (result.status == sphera::CameraOnlyBAStatus::kNoReliablePoints ||
        result.status == sphera::CameraOnlyBAStatus::kTooFewObservations) {
      message << " [--tau_px " << options.tau_px
              << ", --min_observations_per_image "
              << options.min_observations_per_image << "]";
    }
    *error = message.str();
    return false;
  }

  // Success: write poses (through the frames), intrinsics and the reliable
  // points.
  for (size_t i = 0; i < ids.size(); ++i) {
    const Image& image = reconstruction->Image(ids[i]);
    reconstruction->Frame(image.FrameId())
        .SetCamFromWorld(
            image.CameraId(),
            Rigid3d(result.poses[i].rotation, result.poses[i].translation));
  }
  for (const auto& [camera_id, camera] : cameras) {
    reconstruction->Camera(camera_id).params = camera.params;
  }
  std::unordered_map<point3D_t, Eigen::Vector3ub> colors;
  for (const point3D_t point3D_id : point3D_ids) {
    colors[point3D_id] = reconstruction->Point3D(point3D_id).color;
    reconstruction->DeletePoint3D(point3D_id);
  }
  for (const sphera::ReliablePoint& point : result.points) {
    Track track;
    for (const TrackElement& el : elements[point.track_idx]) {
      track.AddElement(el);
    }
    const point3D_t point3D_id = reconstruction->AddPoint3D(
        point.xyz, track, colors.at(point3D_ids[point.track_idx]));
    double sum_px = 0;
    for (size_t k = 0; k < point.errors_rad.size(); ++k) {
      const sphera::RayObservation& obs =
          problem.tracks[point.track_idx][k];
      sum_px += point.errors_rad[k] /
                RadiansPerPixel(cameras.at(camera_of_image[obs.image_idx]));
    }
    reconstruction->Point3D(point3D_id).error =
        sum_px / std::max<size_t>(1, point.errors_rad.size());
  }
  *iterations = static_cast<int>(result.iterations.size());
  for (const sphera::CameraOnlyBAIterationStats& it : result.iterations) {
    LOG(INFO) << "camera-only BA iteration " << it.iteration << ": "
              << it.num_reliable_points << " reliable points, "
              << it.num_reliable_observations << " observations, mean error "
              << it.mean_error_before_rad << " -> " << it.mean_error_after_rad
              << " rad";
  }
  return true;
}

}  // namespace

////////////////////////////////////////////////////////////////////////////////
// SphereBundleAdjustmentOptions
////////////////////////////////////////////////////////////////////////////////

std::string SphereBundleAdjustmentOptions::Check() const {
  std::string error =
      CheckEnum("mode", mode, &SphereBundleAdjustmentModeToString);
  if (error.empty()) {
    error = CheckEnum("residual", residual, &SphereResidualTypeToString);
  }
  if (error.empty()) {
    error = CheckEnum("loss", loss, &SphereBundleAdjustmentLossToString);
  }
  if (!error.empty()) return error;
  if (residual == Residual::PIXEL && mode != Mode::FULL) {
    return "--residual PIXEL is available with --mode FULL only (the "
           "camera-only BA works on rays)";
  }
  if (!(tau_px > 0) || !std::isfinite(tau_px)) {
    return "--tau_px must be > 0, got " + std::to_string(tau_px);
  }
  if (max_iterations < 1) {
    return "--max_iterations must be >= 1, got " +
           std::to_string(max_iterations);
  }
  if (!(loss_scale_px > 0) || !std::isfinite(loss_scale_px)) {
    return "--loss_scale_px must be > 0, got " + std::to_string(loss_scale_px);
  }
  if (min_observations_per_image < 3) {
    return "--min_observations_per_image must be >= 3, got " +
           std::to_string(min_observations_per_image);
  }
  return "";
}

////////////////////////////////////////////////////////////////////////////////
// Public functions
////////////////////////////////////////////////////////////////////////////////

std::map<camera_t, AngularErrorSum> AngularErrorsByCamera(
    const Reconstruction& reconstruction) {
  std::map<camera_t, AngularErrorSum> errors;
  for (const auto& [point3D_id, point3D] : reconstruction.Points3D()) {
    for (const TrackElement& el : point3D.track.Elements()) {
      const Image& image = reconstruction.Image(el.image_id);
      if (!image.HasPose()) continue;
      const Camera& camera = reconstruction.Camera(image.CameraId());
      const std::optional<Eigen::Vector3d> ray =
          camera.CamRayFromImg(image.Point2D(el.point2D_idx).xy);
      if (!ray.has_value()) continue;
      const double angle = sphera::AngleBetweenRays(
          *ray, image.CamFromWorld() * point3D.xyz);
      AngularErrorSum& error = errors[camera.camera_id];
      error.num_observations += 1;
      error.sum_rad += angle;
      error.sum_px += angle / RadiansPerPixel(camera);
    }
  }
  return errors;
}

void MeanAngularError(const Reconstruction& reconstruction,
                      size_t* num_observations,
                      double* mean_rad,
                      double* mean_px) {
  AngularErrorSum total;
  for (const auto& [camera_id, error] : AngularErrorsByCamera(reconstruction)) {
    total.num_observations += error.num_observations;
    total.sum_rad += error.sum_rad;
    total.sum_px += error.sum_px;
  }
  const size_t n = total.num_observations;
  *num_observations = n;
  *mean_rad = n > 0 ? total.sum_rad / n : 0;
  *mean_px = n > 0 ? total.sum_px / n : 0;
}

bool SphereBundleAdjust(const SphereBundleAdjustmentOptions& options,
                        Reconstruction* reconstruction,
                        SphereBundleAdjustmentSummary* summary,
                        std::string* error) {
  const auto start = std::chrono::steady_clock::now();
  *summary = SphereBundleAdjustmentSummary();
  *error = options.Check();
  if (!error->empty()) return false;
  for (const auto& [camera_id, camera] : reconstruction->Cameras()) {
    const std::string params_error = CameraParamsError(camera);
    if (!params_error.empty()) {
      *error = "camera " + std::to_string(camera_id) + ": " + params_error;
      return false;
    }
  }
  image_t gauge_image1 = kInvalidImageId;
  image_t gauge_image2 = kInvalidImageId;
  if (!CheckModel(
          options, *reconstruction, &gauge_image1, &gauge_image2, error)) {
    return false;
  }

  summary->num_points_before = reconstruction->NumPoints3D();
  MeanAngularError(*reconstruction,
                   &summary->num_observations_before,
                   &summary->mean_error_before_rad,
                   &summary->mean_error_before_px);

  Reconstruction work = *reconstruction;
  bool ok = false;
  try {
    if (options.mode == Options::Mode::CAMERA_ONLY) {
      ok = RunCameraOnly(options, &work, &summary->iterations, error);
    } else {
      ok = RunFull(options, gauge_image1, &work, &summary->iterations, error);
    }
  } catch (const std::exception& exception) {
    *error = std::string("bundle adjustment failed: ") + exception.what();
    ok = false;
  }
  if (!ok) return false;
  *reconstruction = work;
  summary->num_points_after = reconstruction->NumPoints3D();
  MeanAngularError(*reconstruction,
                   &summary->num_observations_after,
                   &summary->mean_error_after_rad,
                   &summary->mean_error_after_px);
  summary->seconds = Seconds(start);
  return true;
}

void RunCameraOnlyRefinement(const double tau_px,
                             Reconstruction* reconstruction) {
  if (tau_px <= 0) {
    return;
  }
  SphereBundleAdjustmentOptions options;
  options.mode = SphereBundleAdjustmentOptions::Mode::CAMERA_ONLY;
  options.tau_px = tau_px;
  SphereBundleAdjustmentSummary summary;
  std::string error;
  if (SphereBundleAdjust(options, reconstruction, &summary, &error)) {
    LOG(INFO) << "Camera-only bundle adjustment (tau " << tau_px << " px): "
              << summary.iterations << " iterations, points "
              << summary.num_points_before << " -> "
              << summary.num_points_after << ", mean error "
              << summary.mean_error_before_px << " -> "
              << summary.mean_error_after_px << " px";
  } else {
    LOG(WARNING) << "Camera-only bundle adjustment skipped, the model is "
                    "unchanged: "
                 << error;
  }
}

}  // namespace colmap
