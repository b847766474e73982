#include "estimators/lens_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/SVD>
#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include "camera_models/registry.h"

namespace sphera {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// Pixel reprojection error of one board point (see lens_fit.h):
//   r = ImageFromRay(params, normalize(R X + t)) - observed pixel   [px].
// The ray is normalised because the models are written for unit rays.
// Returning false (point not visible to the model) makes Ceres reject the
// trial step. The equidistant start reuses it with an identity pose and the
// rays as "board points".
template <typename Model>
struct BoardReprojectionCost {
  BoardReprojectionCost(const Eigen::Vector3d& point_in_board,
                        const Eigen::Vector2d& pixel)
      : point_in_board_(point_in_board), pixel_(pixel) {}

  template <typename T>
  bool operator()(const T* params, const T* rotation, const T* translation,
                  T* residual) const {
    const T point[3] = {T(point_in_board_.x()), T(point_in_board_.y()),
                        T(point_in_board_.z())};
    T point_in_cam[3];
    ceres::AngleAxisRotatePoint(rotation, point, point_in_cam);
    T ray_in_cam[3];
    if (!internal::NormalizeRay(point_in_cam[0] + translation[0],
                                point_in_cam[1] + translation[1],
                                point_in_cam[2] + translation[2], ray_in_cam)) {
      return false;
    }
    T pixel[2];
    if (!Model::ImageFromRay(params, ray_in_cam, pixel)) return false;
    residual[0] = pixel[0] - T(pixel_.x());
    residual[1] = pixel[1] - T(pixel_.y());
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& point_in_board,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<BoardReprojectionCost, 2,
                                           Model::kNumParams, 3, 3>(
        new BoardReprojectionCost(point_in_board, pixel));
  }

  const Eigen::Vector3d point_in_board_;
  const Eigen::Vector2d pixel_;
};

// Angle-axis and translation of cam_from_board.
struct BoardPose {
  std::array<double, 3> rotation = {0, 0, 0};
  std::array<double, 3> translation = {0, 0, 0};
};

// One start's unknowns.
struct FitState {
  std::vector<double> params;
  std::vector<BoardPose> poses;  // by image index
};

ceres::Solver::Options LensFitSolverOptions(int max_num_iterations) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = max_num_iterations;
  options.function_tolerance = 1e-12;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  return options;
}

// Unit ray of a pixel through the equidistant lens r = f theta centred at
// center (theta from +z; beyond 90° the ray points backwards).
Eigen::Vector3d EquidistantRay(const Eigen::Vector2d& pixel,
                               const Eigen::Vector2d& center, double focal) {
  const Eigen::Vector2d m = (pixel - center) / focal;
  const double theta = m.norm();
  if (theta == 0) return Eigen::Vector3d::UnitZ();
  const Eigen::Vector2d direction = m / theta;
  return Eigen::Vector3d(std::sin(theta) * direction.x(),
                         std::sin(theta) * direction.y(), std::cos(theta));
}

template <typename Model>
class LensFitter {
 public:
  LensFitter(int width, int height,
             const std::vector<BoardObservation>& observations,
             const std::vector<int>& used_images, int num_images,
             const LensFitOptions& options)
      : width_(width),
        height_(height),
        observations_(observations),
        used_images_(used_images),
        num_images_(num_images),
        options_(options) {
    std::vector<bool> used(num_images, false);
    for (int image : used_images) used[image] = true;
    for (int i = 0; i < static_cast<int>(observations.size()); ++i) {
      if (used[observations[i].image_index]) used_observations_.push_back(i);
    }
  }

  LensFitResult Fit() {
    LensFitResult best;
    best.model_id = Model::kModelId;
    best.model_name = Model::kModelName;
    best.message = "no start gave board poses and visible corners";
    bool have_best = false;
    const Eigen::Vector2d center(width_ / 2.0, height_ / 2.0);
    double max_radius = 0;
    for (int i : used_observations_) {
      max_radius =
          std::max(max_radius, (observations_[i].pixel - center).norm());
    }
    for (double half_angle_deg : options_.initial_half_angles_deg) {
      const double half_angle = half_angle_deg * kDegToRad;
      const double focal = max_radius / half_angle;
      for (bool from_equidistant : {false, true}) {
        FitState state;
        if (!Start(focal, half_angle, from_equidistant, &state)) continue;
        ceres::Solver::Summary summary;
        if (!Refine(&state, &summary)) continue;
        LensFitResult result = Evaluate(state, summary);
        result.initial_focal_length = focal;
        result.initial_from_equidistant = from_equidistant;
        if (!have_best || Better(result, best)) {
          best = result;
          have_best = true;
        }
      }
    }
    return best;
  }

 private:
  // Fewer unseen corners first, then usable parameters, then the smaller RMS.
  static bool Better(const LensFitResult& a, const LensFitResult& b) {
    auto key = [](const LensFitResult& r) {
      return std::make_tuple(r.num_not_visible,
                             r.status == LensFitStatus::kInvalidParams,
                             r.rms_error_px);
    };
    return key(a) < key(b);
  }

  // Initial intrinsics and poses of one start; false if some image's pose
  // cannot be computed.
  bool Start(double focal, double half_angle, bool from_equidistant,
             FitState* state) const {
    state->params = Model::InitialParams(focal, width_, height_);
    const Eigen::Vector2d center(width_ / 2.0, height_ / 2.0);
    if (from_equidistant &&
        !FitToEquidistant(focal, half_angle, center, &state->params)) {
      return false;
    }
    state->poses.assign(num_images_, BoardPose());
    for (int image : used_images_) {
      std::vector<Eigen::Vector3d> points, rays;
      for (int i : used_observations_) {
        const BoardObservation& observation = observations_[i];
        if (observation.image_index != image) continue;
        Eigen::Vector3d ray;
        if (from_equidistant) {
          ray = EquidistantRay(observation.pixel, center, focal);
        } else if (!Model::RayFromImage(state->params.data(),
                                        observation.pixel.data(), ray.data())) {
          continue;
        }
        points.push_back(observation.point_in_board);
        rays.push_back(ray);
      }
      Eigen::Quaterniond rotation;
      Eigen::Vector3d translation;
      if (!BoardPoseFromRays(points, rays, &rotation, &translation)) {
        return false;
      }
      const Eigen::AngleAxisd angle_axis(rotation);
      const Eigen::Vector3d rotation_vector =
          angle_axis.angle() * angle_axis.axis();
      BoardPose& pose = state->poses[image];
      for (int k = 0; k < 3; ++k) {
        pose.rotation[k] = rotation_vector[k];
        pose.translation[k] = translation[k];
      }
    }
    return true;
  }

  // Fits the intrinsics (poses at identity) to the equidistant lens of the
  // given focal length over the rays up to half_angle; in two rounds, since
  // the model's InitialParams may not see every such ray at first.
  bool FitToEquidistant(double focal, double half_angle,
                        const Eigen::Vector2d& center,
                        std::vector<double>* params) const {
    std::vector<BoardObservation> samples;
    constexpr int kNumAngles = 8;
    constexpr int kNumAzimuths = 12;
    for (int a = 1; a <= kNumAngles; ++a) {
      const double theta = half_angle * a / kNumAngles;
      for (int b = 0; b < kNumAzimuths; ++b) {
        const double phi = 2 * internal::kPi * (b + 0.5) / kNumAzimuths;
        BoardObservation sample;
        sample.point_in_board =
            Eigen::Vector3d(std::sin(theta) * std::cos(phi),
                            std::sin(theta) * std::sin(phi), std::cos(theta));
        sample.pixel =
            center +
            focal * theta * Eigen::Vector2d(std::cos(phi), std::sin(phi));
        samples.push_back(sample);
      }
    }
    BoardPose identity;
    for (int round = 0; round < 2; ++round) {
      ceres::Problem problem;
      int num_residuals = 0;
      for (const BoardObservation& sample : samples) {
        if (!Visible(*params, identity, sample)) continue;
        problem.AddResidualBlock(BoardReprojectionCost<Model>::Create(
                                     sample.point_in_board, sample.pixel),
                                 nullptr, params->data(),
                                 identity.rotation.data(),
                                 identity.translation.data());
        ++num_residuals;
      }
      if (num_residuals < Model::kNumParams) return false;
      problem.SetParameterBlockConstant(identity.rotation.data());
      problem.SetParameterBlockConstant(identity.translation.data());
      HoldFixedParams(&problem, params->data());
      ceres::Solver::Summary summary;
      ceres::Solve(LensFitSolverOptions(options_.max_num_iterations), &problem,
                   &summary);
      if (!summary.IsSolutionUsable()) return false;
    }
    return true;
  }

  static void HoldFixedParams(ceres::Problem* problem, double* params) {
    constexpr int kNumFixed = static_cast<int>(Model::kFixedParamsIdxs.size());
    if constexpr (kNumFixed == Model::kNumParams) {
      problem->SetParameterBlockConstant(params);
    } else if constexpr (kNumFixed > 0) {
      problem->SetManifold(
          params, new ceres::SubsetManifold(
                      Model::kNumParams,
                      std::vector<int>(Model::kFixedParamsIdxs.begin(),
                                       Model::kFixedParamsIdxs.end())));
    }
  }

  bool Project(const std::vector<double>& params, const BoardPose& pose,
               const BoardObservation& observation,
               Eigen::Vector2d* residual) const {
    const BoardReprojectionCost<Model> cost(observation.point_in_board,
                                            observation.pixel);
    return cost(params.data(), pose.rotation.data(), pose.translation.data(),
                residual->data());
  }

  bool Visible(const std::vector<double>& params, const BoardPose& pose,
               const BoardObservation& observation) const {
    Eigen::Vector2d residual;
    return Project(params, pose, observation, &residual) &&
           residual.allFinite();
  }

  std::vector<int> VisibleObservations(const FitState& state) const {
    std::vector<int> visible;
    for (int i : used_observations_) {
      const BoardObservation& observation = observations_[i];
      if (Visible(state.params, state.poses[observation.image_index],
                  observation)) {
        visible.push_back(i);
      }
    }
    return visible;
  }

  // Least squares over the given corners; the intrinsics are held when
  // hold_intrinsics is set.
  bool Solve(const std::vector<int>& observation_indices, bool hold_intrinsics,
             FitState* state, ceres::Solver::Summary* summary) const {
    if (static_cast<int>(observation_indices.size()) < Model::kNumParams) {
      return false;
    }
    ceres::Problem problem;
    for (int i : observation_indices) {
      const BoardObservation& observation = observations_[i];
      BoardPose& pose = state->poses[observation.image_index];
      problem.AddResidualBlock(
          BoardReprojectionCost<Model>::Create(observation.point_in_board,
                                               observation.pixel),
          nullptr, state->params.data(), pose.rotation.data(),
          pose.translation.data());
    }
    if (hold_intrinsics) {
      problem.SetParameterBlockConstant(state->params.data());
    } else {
      HoldFixedParams(&problem, state->params.data());
    }
    ceres::Solve(LensFitSolverOptions(options_.max_num_iterations), &problem,
                 summary);
    return summary->IsSolutionUsable();
  }

  bool Refine(FitState* state, ceres::Solver::Summary* summary) const {
    if (!Solve(VisibleObservations(*state), /*hold_intrinsics=*/true, state,
               summary)) {
      return false;
    }
    std::vector<int> visible = VisibleObservations(*state);
    if (!Solve(visible, /*hold_intrinsics=*/false, state, summary)) {
      return false;
    }
    // The fitted model may see corners the start did not.
    const std::vector<int> now_visible = VisibleObservations(*state);
    if (now_visible.size() > visible.size()) {
      FitState retry = *state;
      ceres::Solver::Summary retry_summary;
      if (Solve(now_visible, /*hold_intrinsics=*/false, &retry,
                &retry_summary)) {
        *state = retry;
        *summary = retry_summary;
      }
    }
    return true;
  }

  LensFitResult Evaluate(const FitState& state,
                         const ceres::Solver::Summary& summary) const {
    LensFitResult result;
    result.model_id = Model::kModelId;
    result.model_name = Model::kModelName;
    result.params = state.params;
    result.num_observations = static_cast<int>(used_observations_.size());
    result.observation_errors_px.assign(observations_.size(), -1.0);
    double sum_squared = 0;
    int num_visible = 0;
    std::vector<double> image_sum_squared(num_images_, 0.0);
    std::vector<int> image_num_visible(num_images_, 0);
    for (int i : used_observations_) {
      const BoardObservation& observation = observations_[i];
      Eigen::Vector2d residual;
      if (!Project(state.params, state.poses[observation.image_index],
                   observation, &residual) ||
          !residual.allFinite()) {
        ++result.num_not_visible;
        continue;
      }
      result.observation_errors_px[i] = residual.norm();
      sum_squared += residual.squaredNorm();
      result.max_error_px = std::max(result.max_error_px, residual.norm());
      ++num_visible;
      image_sum_squared[observation.image_index] += residual.squaredNorm();
      ++image_num_visible[observation.image_index];
    }
    result.rms_error_px =
        num_visible > 0 ? std::sqrt(sum_squared / num_visible) : 0.0;
    result.image_rms_error_px.assign(num_images_, 0.0);
    for (int image = 0; image < num_images_; ++image) {
      if (image_num_visible[image] > 0) {
        result.image_rms_error_px[image] =
            std::sqrt(image_sum_squared[image] / image_num_visible[image]);
      }
    }
    result.cam_from_board_rotations.assign(num_images_,
                                           Eigen::Quaterniond::Identity());
    result.cam_from_board_translations.assign(num_images_,
                                              Eigen::Vector3d::Zero());
    for (int image : used_images_) {
      const BoardPose& pose = state.poses[image];
      const Eigen::Vector3d rotation_vector(pose.rotation.data());
      const double angle = rotation_vector.norm();
      result.cam_from_board_rotations[image] =
          angle > 0 ? Eigen::Quaterniond(
                          Eigen::AngleAxisd(angle, rotation_vector / angle))
                    : Eigen::Quaterniond::Identity();
      result.cam_from_board_translations[image] =
          Eigen::Vector3d(pose.translation.data());
    }
    const std::string check = Model::CheckParams(state.params, width_, height_);
    if (summary.termination_type != ceres::CONVERGENCE) {
      result.status = LensFitStatus::kNoConvergence;
      result.message = summary.message;
    } else if (!check.empty()) {
      result.status = LensFitStatus::kInvalidParams;
      result.message = check;
    } else {
      result.status = LensFitStatus::kSuccess;
    }
    return result;
  }

  const int width_;
  const int height_;
  const std::vector<BoardObservation>& observations_;
  const std::vector<int> used_images_;
  const int num_images_;
  const LensFitOptions& options_;
  std::vector<int> used_observations_;
};

}  // namespace

void LensFitOptions::Check() const {
  if (initial_half_angles_deg.empty()) {
    throw std::invalid_argument(
        "LensFitOptions.initial_half_angles_deg must not be empty");
  }
  for (double angle : initial_half_angles_deg) {
    if (!(angle > 0 && angle < 180)) {
      throw std::invalid_argument(
          "LensFitOptions.initial_half_angles_deg: " + std::to_string(angle) +
          " is not in (0, 180) degrees");
    }
  }
  if (max_num_iterations < 1) {
    throw std::invalid_argument(
        "LensFitOptions.max_num_iterations must be at least 1");
  }
  if (min_observations_per_image < 4) {
    throw std::invalid_argument(
        "LensFitOptions.min_observations_per_image must be at least 4 (a "
        "homography)");
  }
}

const char* LensFitStatusName(LensFitStatus status) {
  switch (status) {
    case LensFitStatus::kSuccess:
      return "success";
    case LensFitStatus::kNoConvergence:
      return "no_convergence";
    case LensFitStatus::kInvalidParams:
      return "invalid_params";
    case LensFitStatus::kFailure:
      return "failure";
  }
  return "unknown";
}

bool BoardPoseFromRays(const std::vector<Eigen::Vector3d>& points_in_board,
                       const std::vector<Eigen::Vector3d>& rays_in_cam,
                       Eigen::Quaterniond* cam_from_board_rotation,
                       Eigen::Vector3d* cam_from_board_translation) {
  const int n = static_cast<int>(points_in_board.size());
  if (n < 4 || static_cast<int>(rays_in_cam.size()) != n) return false;
  // Hartley normalisation of the board coordinates: q = T (X, Y, 1).
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector3d& point : points_in_board) {
    centroid += point.head<2>();
  }
  centroid /= n;
  double mean_distance = 0;
  for (const Eigen::Vector3d& point : points_in_board) {
    mean_distance += (point.head<2>() - centroid).norm();
  }
  mean_distance /= n;
  if (!(mean_distance > 0)) return false;
  const double scale = std::sqrt(2.0) / mean_distance;
  Eigen::Matrix3d normalization;
  normalization << scale, 0, -scale * centroid.x(), 0, scale,
      -scale * centroid.y(), 0, 0, 1;
  // ray x (H q) = 0, three rows per point (any two are independent); with h
  // the row-major entries of H, H q = kron(I, q^T) h.
  Eigen::MatrixXd A(3 * n, 9);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d q =
        normalization *
        Eigen::Vector3d(points_in_board[i].x(), points_in_board[i].y(), 1.0);
    const Eigen::Vector3d r = rays_in_cam[i].normalized();
    Eigen::Matrix3d cross;
    cross << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
    Eigen::Matrix<double, 3, 9> kron = Eigen::Matrix<double, 3, 9>::Zero();
    for (int row = 0; row < 3; ++row) {
      kron.block<1, 3>(row, 3 * row) = q.transpose();
    }
    A.block<3, 9>(3 * i, 0) = cross * kron;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::VectorXd& singular = svd.singularValues();
  // A one-dimensional null space: the second smallest singular value must
  // stand clear of zero (collinear points leave a larger one).
  if (!(singular(7) > 1e-9 * singular(0))) return false;
  const Eigen::Matrix<double, 9, 1> h = svd.matrixV().col(8);
  Eigen::Matrix3d H;
  H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  H = H * normalization;  // now maps (X, Y, 1) to rays
  // H ~ [r1 r2 t]; the scale makes r1, r2 unit on average, its sign puts the
  // points in front along their rays: ray . (R X + t) > 0.
  double lambda = 2.0 / (H.col(0).norm() + H.col(1).norm());
  double front = 0;
  for (int i = 0; i < n; ++i) {
    front += rays_in_cam[i].normalized().dot(
        H *
        Eigen::Vector3d(points_in_board[i].x(), points_in_board[i].y(), 1.0));
  }
  if (front < 0) lambda = -lambda;
  const Eigen::Matrix3d M = lambda * H;
  Eigen::Matrix3d R;
  R.col(0) = M.col(0);
  R.col(1) = M.col(1);
  R.col(2) = M.col(0).cross(M.col(1));
  const Eigen::JacobiSVD<Eigen::Matrix3d> rotation_svd(
      R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (rotation_svd.matrixU() * rotation_svd.matrixV().transpose())
                .determinant();
  R = rotation_svd.matrixU() * D * rotation_svd.matrixV().transpose();
  if (!R.allFinite() || !M.col(2).allFinite()) return false;
  *cam_from_board_rotation = Eigen::Quaterniond(R);
  *cam_from_board_translation = M.col(2);
  return true;
}

LensFitResult FitLens(int model_id, int width, int height,
                      const std::vector<BoardObservation>& observations,
                      const LensFitOptions& options) {
  options.Check();
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("FitLens: image size " + std::to_string(width) +
                                "x" + std::to_string(height) +
                                " is not positive");
  }
  int num_images = 0;
  for (const BoardObservation& observation : observations) {
    if (observation.image_index < 0) {
      throw std::invalid_argument("FitLens: negative image index " +
                                  std::to_string(observation.image_index));
    }
    if (observation.point_in_board.z() != 0) {
      throw std::invalid_argument(
          "FitLens: board point off the plane z = 0 in image " +
          std::to_string(observation.image_index));
    }
    if (!observation.point_in_board.allFinite() ||
        !observation.pixel.allFinite()) {
      throw std::invalid_argument("FitLens: a non-finite value in image " +
                                  std::to_string(observation.image_index));
    }
    num_images = std::max(num_images, observation.image_index + 1);
  }
  std::vector<int> counts(num_images, 0);
  for (const BoardObservation& observation : observations) {
    ++counts[observation.image_index];
  }
  std::vector<int> used_images, skipped_images;
  for (int image = 0; image < num_images; ++image) {
    if (counts[image] >= options.min_observations_per_image) {
      used_images.push_back(image);
    } else if (counts[image] > 0) {
      skipped_images.push_back(image);
    }
  }
  return internal::VisitModel(model_id, [&](auto model) {
    using Model = decltype(model);
    LensFitResult result;
    if (used_images.empty()) {
      result.model_id = Model::kModelId;
      result.model_name = Model::kModelName;
      result.message = "no image has " +
                       std::to_string(options.min_observations_per_image) +
                       " corners";
    } else {
      result = LensFitter<Model>(width, height, observations, used_images,
                                 num_images, options)
                   .Fit();
    }
    result.skipped_images = skipped_images;
    return result;
  });
}

}  // namespace sphera
