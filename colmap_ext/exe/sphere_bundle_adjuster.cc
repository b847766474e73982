#include "colmap_ext/exe/sphere_bundle_adjuster.h"

#include "colmap_ext/sensor/camera_params_held.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/estimators/bundle_adjustment.h"
#include "colmap/estimators/cost_functions.h"
#include "colmap/util/logging.h"
#include "colmap/util/misc.h"

#include "estimators/camera_only_bundle_adjustment.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include <ceres/ceres.h>

namespace colmap {
namespace {

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                       start)
      .count();
}

std::vector<image_t> SortedRegImageIds(const Reconstruction& reconstruction) {
  std::vector<image_t> ids = reconstruction.RegImageIds();
  std::sort(ids.begin(), ids.end());
  return ids;
}

void ParameterizeCamera(ceres::Problem* problem, Camera* camera,
                        bool refine) {
  if (!problem->HasParameterBlock(camera->params.data())) return;
  // When intrinsics are refined: all but the principal point (held, as
  // COLMAP's default) and the model's fixed parameters.
  const std::vector<int> constant = CameraParamsHeldConstant(
      *camera, /*refine_focal_length=*/true, /*refine_principal_point=*/false,
      /*refine_extra_params=*/true);
  if (!refine || constant.size() == camera->params.size()) {
    problem->SetParameterBlockConstant(camera->params.data());
  } else if (!constant.empty()) {
    SetSubsetManifold(static_cast<int>(camera->params.size()), constant,
                      problem, camera->params.data());
  }
}

double MeanRadPerPx(const Reconstruction& reconstruction) {
  double sum = 0;
  for (const auto& [id, camera] : reconstruction.Cameras()) {
    sum += camera.CamRayFromImgThreshold(1.0);
  }
  return reconstruction.NumCameras() ? sum / reconstruction.NumCameras() : 1;
}

// Checks shared by both modes: >= 2 registered images, every registered
// image with enough observations of points with >= 2 observations, and the
// first two images not at the same centre.
bool CheckModel(const SphereBundleAdjusterOptions& options,
                const Reconstruction& reconstruction, std::string* error) {
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
  for (const auto& [id, point] : reconstruction.Points3D()) {
    if (point.track.Length() < 2) continue;
    for (const auto& el : point.track.Elements()) ++counts[el.image_id];
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
  const double baseline = (reconstruction.Image(ids[0]).ProjectionCenter() -
                           reconstruction.Image(ids[1]).ProjectionCenter())
                              .norm();
  if (!(baseline > 1e-12)) {
    *error = "degenerate geometry: the first two images " +
             reconstruction.Image(ids[0]).Name() + " and " +
             reconstruction.Image(ids[1]).Name() +
             " share their centre, the scale gauge cannot be fixed";
    return false;
  }
  return true;
}

void SetUpFullGauge(const std::vector<image_t>& ids,
                    const Reconstruction& reconstruction,
                    BundleAdjustmentConfig* config) {
  config->SetConstantCamPose(ids[0]);
  // Fix the largest translation coordinate of the second image (scale).
  const Eigen::Vector3d t =
      reconstruction.Image(ids[1]).CamFromWorld().translation;
  int idx = 0;
  t.cwiseAbs().maxCoeff(&idx);
  config->SetConstantCamPositions(ids[1], {idx});
}

bool RunFullAngular(const SphereBundleAdjusterOptions& options,
                    Reconstruction* reconstruction, int* iterations,
                    std::string* error) {
  const std::vector<image_t> ids = SortedRegImageIds(*reconstruction);
  BundleAdjustmentOptions ba_options;
  ba_options.refine_focal_length = options.refine_intrinsics;
  ba_options.refine_extra_params = options.refine_intrinsics;
  ba_options.refine_principal_point = false;
  ba_options.print_summary = false;
  ba_options.solver_options.max_num_iterations =
      std::max(100, options.max_iterations);
  ba_options.solver_options.function_tolerance = 1e-12;
  ba_options.solver_options.num_threads = 1;
  if (options.loss == "cauchy") {
    ba_options.loss_function_type =
        BundleAdjustmentOptions::LossFunctionType::CAUCHY;
    ba_options.loss_function_scale = options.loss_scale_px;
  }
  BundleAdjustmentConfig config;
  for (const image_t id : ids) {
    config.AddImage(id);
    if (!options.refine_intrinsics) {
      config.SetConstantCamIntrinsics(reconstruction->Image(id).CameraId());
    }
  }
  SetUpFullGauge(ids, *reconstruction, &config);
  BundleAdjuster adjuster(ba_options, config);
  if (!adjuster.Solve(reconstruction)) {
    *error = "COLMAP's bundle adjustment failed: " +
             adjuster.Summary().BriefReport();
    return false;
  }
  *iterations = static_cast<int>(adjuster.Summary().iterations.size());
  return true;
}

bool RunFullPixel(const SphereBundleAdjusterOptions& options,
                  Reconstruction* reconstruction, int* iterations,
                  std::string* error) {
  const std::vector<image_t> ids = SortedRegImageIds(*reconstruction);
  std::unordered_set<image_t> registered(ids.begin(), ids.end());
  std::unique_ptr<ceres::LossFunction> loss;
  if (options.loss == "cauchy") {
    loss = std::make_unique<ceres::CauchyLoss>(options.loss_scale_px);
  }
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem pixel_problem(problem_options);
  size_t num_skipped = 0;
  auto* ordering = new ceres::ParameterBlockOrdering;
  for (auto& [point3D_id, point] : reconstruction->Points3D()) {
    Point3D& point3D = reconstruction->Point3D(point3D_id);
    for (const auto& el : point3D.track.Elements()) {
      if (!registered.count(el.image_id)) continue;
      Image& image = reconstruction->Image(el.image_id);
      Camera& camera = reconstruction->Camera(image.CameraId());
      const Eigen::Vector2d& xy = image.Point2D(el.point2D_idx).xy;
      Eigen::Vector2d projected;
      if (!camera.ImgFromCamRay(image.CamFromWorld() * point3D.xyz,
                                &projected)) {
        ++num_skipped;  // not visible at the start: no residual
        continue;
      }
      Rigid3d& pose = image.CamFromWorld();
      pixel_problem.AddResidualBlock(
          CameraCostFunction<PixelReprojErrorCostFunction>(camera.model_id,
                                                           xy),
          loss.get(), pose.rotation.coeffs().data(), pose.translation.data(),
          point3D.xyz.data(), camera.params.data());
    }
    if (pixel_problem.HasParameterBlock(point3D.xyz.data())) {
      ordering->AddElementToGroup(point3D.xyz.data(), 0);
    }
  }
  for (const image_t id : ids) {
    Rigid3d& pose = reconstruction->Image(id).CamFromWorld();
    if (!pixel_problem.HasParameterBlock(pose.rotation.coeffs().data())) {
      continue;
    }
    SetQuaternionManifold(&pixel_problem, pose.rotation.coeffs().data());
    ordering->AddElementToGroup(pose.rotation.coeffs().data(), 1);
    ordering->AddElementToGroup(pose.translation.data(), 1);
    if (id == ids[0]) {
      pixel_problem.SetParameterBlockConstant(pose.rotation.coeffs().data());
      pixel_problem.SetParameterBlockConstant(pose.translation.data());
    } else if (id == ids[1]) {
      int idx = 0;
      pose.translation.cwiseAbs().maxCoeff(&idx);
      SetSubsetManifold(3, {idx}, &pixel_problem, pose.translation.data());
    }
  }
  for (auto& [camera_id, camera_ref] : reconstruction->Cameras()) {
    Camera& camera = reconstruction->Camera(camera_id);
    if (!pixel_problem.HasParameterBlock(camera.params.data())) continue;
    ParameterizeCamera(&pixel_problem, &camera, options.refine_intrinsics);
    ordering->AddElementToGroup(camera.params.data(), 1);
  }
  if (num_skipped > 0) {
    LOG(WARNING) << "pixel residual: " << num_skipped
                 << " observations outside the field of view were skipped";
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type =
      ids.size() <= 50 ? ceres::DENSE_SCHUR : ceres::SPARSE_SCHUR;
  if (!ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) &&
      solver_options.linear_solver_type == ceres::SPARSE_SCHUR) {
    solver_options.linear_solver_type = ceres::ITERATIVE_SCHUR;
    solver_options.preconditioner_type = ceres::SCHUR_JACOBI;
  }
  solver_options.linear_solver_ordering.reset(ordering);
  solver_options.max_num_iterations = std::max(100, options.max_iterations);
  solver_options.function_tolerance = 1e-12;
  solver_options.gradient_tolerance = 0;
  solver_options.parameter_tolerance = 0;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &pixel_problem, &summary);
  if (!summary.IsSolutionUsable()) {
    *error = "pixel bundle adjustment failed: " + summary.BriefReport();
    return false;
  }
  *iterations = static_cast<int>(summary.iterations.size());
  return true;
}

bool RunCameraOnly(const SphereBundleAdjusterOptions& options,
                   Reconstruction* reconstruction, int* iterations,
                   std::string* error) {
  const std::vector<image_t> ids = SortedRegImageIds(*reconstruction);
  std::unordered_map<image_t, int> image_idx;
  sphera::CameraOnlyBAProblem problem;
  for (size_t i = 0; i < ids.size(); ++i) {
    image_idx[ids[i]] = static_cast<int>(i);
    const Rigid3d& pose = reconstruction->Image(ids[i]).CamFromWorld();
    sphera::CameraPose p;
    p.rotation = pose.rotation;
    p.translation = pose.translation;
    problem.poses.push_back(p);
  }
  // Tracks in point id order; elements parallel to the rays.
  std::vector<point3D_t> point_ids;
  for (const auto& [id, point] : reconstruction->Points3D()) {
    point_ids.push_back(id);
  }
  std::sort(point_ids.begin(), point_ids.end());
  std::vector<std::vector<TrackElement>> elements;
  size_t num_unliftable = 0;
  for (const point3D_t id : point_ids) {
    const Point3D& point = reconstruction->Point3D(id);
    sphera::RayTrack track;
    std::vector<TrackElement> els;
    for (const auto& el : point.track.Elements()) {
      const auto it = image_idx.find(el.image_id);
      if (it == image_idx.end()) continue;
      const Image& image = reconstruction->Image(el.image_id);
      const Camera& camera = reconstruction->Camera(image.CameraId());
      sphera::RayObservation obs;
      obs.image_idx = it->second;
      if (!camera.CamRayFromImg(image.Point2D(el.point2D_idx).xy, &obs.ray)) {
        ++num_unliftable;
        continue;
      }
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
  for (const auto& [id, camera] : reconstruction->Cameras()) {
    cameras[id] = camera;
  }
  std::vector<camera_t> camera_of_image(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) {
    camera_of_image[i] = reconstruction->Image(ids[i]).CameraId();
  }

  sphera::CameraOnlyBAOptions ba;
  ba.tau_rad_fn = [&](int i) {
    return options.tau_px *
           cameras.at(camera_of_image[i]).CamRayFromImgThreshold(1.0);
  };
  ba.max_iterations = options.max_iterations;
  ba.min_observations_per_image = options.min_observations_per_image;
  if (options.loss == "cauchy") {
    ba.loss = sphera::CameraOnlyBALoss::kCauchy;
    ba.loss_scale_rad = options.loss_scale_px * MeanRadPerPx(*reconstruction);
  }
  ba.gauge = sphera::GaugeFixing::kFirstTwoCameras;

  if (options.refine_intrinsics) {
    // Intrinsics of the cameras with focal parameters, together with the
    // poses of their images (focal length and pose are coupled; the two gauge
    // images stay fixed), on the fixed reliable points.
    ba.intrinsics_step = [&](std::vector<sphera::CameraPose>* poses,
                             const std::vector<sphera::ReliablePoint>& points,
                             std::vector<sphera::RayTrack>* tracks) {
      std::vector<Eigen::Vector4d> qs(poses->size());
      std::vector<Eigen::Vector3d> ts(poses->size());
      for (size_t i = 0; i < poses->size(); ++i) {
        qs[i] = (*poses)[i].rotation.coeffs();
        ts[i] = (*poses)[i].translation;
      }
      ceres::Problem intrinsics_problem;
      for (const auto& point : points) {
        const auto& els = elements[point.track_idx];
        const auto& track = (*tracks)[point.track_idx];
        for (size_t k = 0; k < track.size(); ++k) {
          const int i = track[k].image_idx;
          Camera& camera = cameras.at(camera_of_image[i]);
          if (camera.FocalLengthIdxs().size() == 0) continue;
          const Eigen::Vector2d& xy =
              reconstruction->Image(ids[i]).Point2D(els[k].point2D_idx).xy;
          intrinsics_problem.AddResidualBlock(
              CameraCostFunction<ReprojErrorConstantPoint3DCostFunction>(
                  camera.model_id, xy, point.xyz),
              options.loss == "cauchy"
                  ? new ceres::CauchyLoss(options.loss_scale_px)
                  : nullptr,
              qs[i].data(), ts[i].data(), camera.params.data());
        }
      }
      for (size_t i = 0; i < poses->size(); ++i) {
        if (!intrinsics_problem.HasParameterBlock(qs[i].data())) continue;
        SetQuaternionManifold(&intrinsics_problem, qs[i].data());
        if (i < 2) {
          intrinsics_problem.SetParameterBlockConstant(qs[i].data());
          intrinsics_problem.SetParameterBlockConstant(ts[i].data());
        }
      }
      if (intrinsics_problem.NumResidualBlocks() == 0) return true;
      for (auto& [id, camera] : cameras) {
        ParameterizeCamera(&intrinsics_problem, &camera, true);
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
            Eigen::Quaterniond(qs[i](3), qs[i](0), qs[i](1), qs[i](2))
                .normalized();
        (*poses)[i].translation = ts[i];
      }
      // Re-lift the rays of every observation (the intrinsics changed).
      for (size_t j = 0; j < tracks->size(); ++j) {
        for (size_t k = 0; k < (*tracks)[j].size(); ++k) {
          auto& obs = (*tracks)[j][k];
          const Camera& camera = cameras.at(camera_of_image[obs.image_idx]);
          const Eigen::Vector2d& xy = reconstruction->Image(ids[obs.image_idx])
                                          .Point2D(elements[j][k].point2D_idx)
                                          .xy;
          if (!camera.CamRayFromImg(xy, &obs.ray)) return false;
        }
      }
      return true;
    };
  }

  const sphera::CameraOnlyBAResult result =
      sphera::CameraOnlyBundleAdjustment(problem, ba);
  if (!result.Success()) {
    // The failing image by its file name.
    std::string text = result.message;
    if (result.image_idx >= 0 &&
        result.image_idx < static_cast<int>(ids.size())) {
      text = "image " + reconstruction->Image(ids[result.image_idx]).Name() +
             " " + text;
    }
    std::ostringstream msg;
    msg << "camera-only BA failed (" << sphera::CameraOnlyBAStatusName(result.status)
        << "): " << text;
    if (result.status == sphera::CameraOnlyBAStatus::kNoReliablePoints ||
        result.status == sphera::CameraOnlyBAStatus::kTooFewObservations) {
      msg << " [--tau_px " << options.tau_px
          << ", --min_observations_per_image "
          << options.min_observations_per_image << "]";
    }
    text = msg.str();
    *error = text;
    return false;
  }

  // Success: write poses, intrinsics and the reliable points.
  for (size_t i = 0; i < ids.size(); ++i) {
    Rigid3d& pose = reconstruction->Image(ids[i]).CamFromWorld();
    pose.rotation = result.poses[i].rotation;
    pose.translation = result.poses[i].translation;
  }
  for (const auto& [id, camera] : cameras) {
    reconstruction->Camera(id).params = camera.params;
  }
  std::unordered_map<point3D_t, Eigen::Vector3ub> colors;
  for (const point3D_t id : point_ids) {
    colors[id] = reconstruction->Point3D(id).color;
    reconstruction->DeletePoint3D(id);
  }
  for (const auto& point : result.points) {
    Track track;
    for (const auto& el : elements[point.track_idx]) track.AddElement(el);
    const point3D_t new_id = reconstruction->AddPoint3D(
        point.xyz, track, colors.at(point_ids[point.track_idx]));
    double sum_px = 0;
    for (size_t k = 0; k < point.errors_rad.size(); ++k) {
      const auto& obs = problem.tracks[point.track_idx][k];
      sum_px += point.errors_rad[k] /
                cameras.at(camera_of_image[obs.image_idx])
                    .CamRayFromImgThreshold(1.0);
    }
    reconstruction->Point3D(new_id).error = sum_px / point.errors_rad.size();
  }
  *iterations = static_cast<int>(result.iterations.size());
  for (const auto& it : result.iterations) {
    LOG(INFO) << "camera-only BA iteration " << it.iteration << ": "
              << it.num_reliable_points << " reliable points, "
              << it.num_reliable_observations << " observations, mean error "
              << it.mean_error_before_rad << " -> " << it.mean_error_after_rad
              << " rad";
  }
  return true;
}

}  // namespace

void MeanAngularError(const Reconstruction& reconstruction,
                      size_t* num_observations, double* mean_rad,
                      double* mean_px) {
  size_t n = 0;
  double sum_rad = 0, sum_px = 0;
  for (const auto& [id, point] : reconstruction.Points3D()) {
    for (const auto& el : point.track.Elements()) {
      const Image& image = reconstruction.Image(el.image_id);
      if (!image.IsRegistered()) continue;
      const Camera& camera = reconstruction.Camera(image.CameraId());
      Eigen::Vector3d ray;
      if (!camera.CamRayFromImg(image.Point2D(el.point2D_idx).xy, &ray)) {
        continue;
      }
      const Eigen::Vector3d v = image.CamFromWorld() * point.xyz;
      const double angle = std::atan2(ray.cross(v).norm(), ray.dot(v));
      sum_rad += angle;
      sum_px += angle / camera.CamRayFromImgThreshold(1.0);
      ++n;
    }
  }
  *num_observations = n;
  *mean_rad = n ? sum_rad / n : 0;
  *mean_px = n ? sum_px / n : 0;
}

bool SphereBundleAdjust(const SphereBundleAdjusterOptions& options,
                        Reconstruction* reconstruction,
                        SphereBundleAdjusterSummary* summary,
                        std::string* error) {
  const auto start = std::chrono::steady_clock::now();
  *summary = SphereBundleAdjusterSummary();
  if (options.mode != "camera_only" && options.mode != "full") {
    *error = "--mode must be camera_only or full, got '" + options.mode + "'";
    return false;
  }
  if (options.residual != "angular" && options.residual != "pixel") {
    *error = "--residual must be angular or pixel, got '" + options.residual +
             "'";
    return false;
  }
  if (options.residual == "pixel" && options.mode != "full") {
    *error =
        "--residual pixel is available with --mode full only (the "
        "camera-only BA works on rays)";
    return false;
  }
  if (!(options.tau_px > 0) || !std::isfinite(options.tau_px)) {
    *error = "--tau_px must be > 0, got " + std::to_string(options.tau_px);
    return false;
  }
  if (options.max_iterations < 1) {
    *error = "--max_iterations must be >= 1";
    return false;
  }
  if (options.loss != "none" && options.loss != "cauchy") {
    *error = "--loss must be none or cauchy, got '" + options.loss + "'";
    return false;
  }
  if (options.loss == "cauchy" && !(options.loss_scale_px > 0)) {
    *error = "--loss_scale_px must be > 0";
    return false;
  }
  if (options.min_observations_per_image < 3) {
    *error = "--min_observations_per_image must be >= 3";
    return false;
  }
  for (const auto& [id, camera] : reconstruction->Cameras()) {
    const std::string params_error = camera.ParamsError();
    if (!params_error.empty()) {
      *error = "camera " + std::to_string(id) + ": " + params_error;
      return false;
    }
  }
  if (!CheckModel(options, *reconstruction, error)) return false;

  summary->num_points_before = reconstruction->NumPoints3D();
  MeanAngularError(*reconstruction, &summary->num_observations_before,
                   &summary->mean_error_before_rad,
                   &summary->mean_error_before_px);

  Reconstruction work = *reconstruction;
  bool ok = false;
  if (options.mode == "camera_only") {
    ok = RunCameraOnly(options, &work, &summary->iterations, error);
  } else if (options.residual == "angular") {
    ok = RunFullAngular(options, &work, &summary->iterations, error);
  } else {
    ok = RunFullPixel(options, &work, &summary->iterations, error);
  }
  if (!ok) return false;
  *reconstruction = std::move(work);
  summary->num_points_after = reconstruction->NumPoints3D();
  MeanAngularError(*reconstruction, &summary->num_observations_after,
                   &summary->mean_error_after_rad,
                   &summary->mean_error_after_px);
  summary->seconds = Seconds(start);
  return true;
}

void RunCameraOnlyRefinement(const double tau_px,
                             Reconstruction* reconstruction) {
  SphereBundleAdjusterOptions options;
  options.mode = "camera_only";
  options.tau_px = tau_px;
  SphereBundleAdjusterSummary summary;
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

int RunSphereBundleAdjuster(int argc, char** argv) {
  std::string input_path;
  std::string output_path;
  SphereBundleAdjusterOptions options;

  OptionManager option_manager;
  option_manager.AddRequiredOption("input_path", &input_path);
  option_manager.AddRequiredOption("output_path", &output_path);
  option_manager.AddDefaultOption("mode", &options.mode,
                                  "camera_only or full");
  option_manager.AddDefaultOption("tau_px", &options.tau_px);
  option_manager.AddDefaultOption("max_iterations", &options.max_iterations);
  option_manager.AddDefaultOption("refine_intrinsics",
                                  &options.refine_intrinsics);
  option_manager.AddDefaultOption("residual", &options.residual,
                                  "angular or pixel");
  option_manager.AddDefaultOption("loss", &options.loss, "none or cauchy");
  option_manager.AddDefaultOption("loss_scale_px", &options.loss_scale_px);
  option_manager.AddDefaultOption("min_observations_per_image",
                                  &options.min_observations_per_image);
  option_manager.Parse(argc, argv);

  if (!ExistsDir(input_path)) {
    LOG(ERROR) << "--input_path: " << input_path << " is not a directory";
    return EXIT_FAILURE;
  }
  if (ExistsFile(output_path)) {
    LOG(ERROR) << "--output_path: " << output_path
               << " is a file, not a directory";
    return EXIT_FAILURE;
  }
  Reconstruction reconstruction;
  try {
    reconstruction.Read(input_path);
  } catch (const std::exception& e) {
    LOG(ERROR) << "--input_path: cannot read the model " << input_path << ": "
               << e.what();
    return EXIT_FAILURE;
  }

  SphereBundleAdjusterSummary summary;
  std::string error;
  if (!SphereBundleAdjust(options, &reconstruction, &summary, &error)) {
    LOG(ERROR) << "sphere_bundle_adjuster: " << error
               << "; nothing was written";
    return EXIT_FAILURE;
  }

  std::ostringstream out;
  out << std::setprecision(6);
  out << "sphere_bundle_adjuster: mode " << options.mode << ", residual "
      << options.residual;
  if (options.mode == "camera_only") out << ", tau " << options.tau_px << " px";
  out << "\n  iterations:        " << summary.iterations
      << "\n  points:            " << summary.num_points_before << " -> "
      << summary.num_points_after
      << (options.mode == "camera_only" ? " (reliable, re-triangulated)" : "")
      << "\n  observations:      " << summary.num_observations_before << " -> "
      << summary.num_observations_after
      << "\n  mean angular error: " << summary.mean_error_before_rad
      << " rad (" << summary.mean_error_before_px << " px) -> "
      << summary.mean_error_after_rad << " rad ("
      << summary.mean_error_after_px << " px)"
      << "\n  time:              " << summary.seconds << " s\n";
  std::cout << out.str() << std::flush;

  try {
    CreateDirIfNotExists(output_path, true);
    reconstruction.Write(output_path);
  } catch (const std::exception& e) {
    LOG(ERROR) << "--output_path: cannot write " << output_path << ": "
               << e.what();
    return EXIT_FAILURE;
  }
  std::cout << "  written to:        " << output_path << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace colmap
