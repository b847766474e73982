// The analytic angular cost functions that bundle adjustment uses for
// spherical cameras (single cameras and lenses of rigs) against the autodiff
// functors they replace: the same residual, the same Jacobians for every
// parameter block (any subset asked for), for points in front of, beside and
// behind each lens, at zero error, and the same refusal of a pixel outside
// the image. And the Jacobian of the camera parameters against finite
// differences of the cost itself: the residual's unit (pixels per radian)
// is fixed when the cost is made, so the derivatives are those of the cost
// that the solver sees.
#include "colmap_ext/estimators/sphere_cost_functions.h"

#include "colmap/geometry/rigid3.h"
#include "colmap/sensor/models.h"

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <typeinfo>
#include <vector>

#include <gtest/gtest.h>

namespace colmap {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The autodiff reference of AngularRigReprojErrorCostFunction: the same
// residual (rig_from_world, then cam_from_rig), differentiated by Ceres.
template <typename CameraModel>
class AngularRigReprojErrorCostFunctor
    : public AutoDiffCostFunctor<AngularRigReprojErrorCostFunctor<CameraModel>,
                                 2,
                                 3,
                                 7,
                                 7,
                                 CameraModel::num_params> {
 public:
  AngularRigReprojErrorCostFunctor(const double* camera_params,
                                   const Eigen::Vector2d& point2D)
      : point2D_(point2D),
        weight_(AngularResidualWeight<CameraModel>(camera_params, point2D)) {}

  template <typename T>
  bool operator()(const T* const point3D_in_world,
                  const T* const cam_from_rig,
                  const T* const rig_from_world,
                  const T* const camera_params,
                  T* residuals) const {
    const Eigen::Matrix<T, 3, 1> point3D_in_cam =
        EigenQuaternionMap<T>(cam_from_rig) *
            (EigenQuaternionMap<T>(rig_from_world) *
                 EigenVector3Map<T>(point3D_in_world) +
             EigenVector3Map<T>(rig_from_world + 4)) +
        EigenVector3Map<T>(cam_from_rig + 4);
    return AngularReprojResidual<CameraModel>(
        camera_params, point2D_, point3D_in_cam, weight_, residuals);
  }

 private:
  const Eigen::Vector2d point2D_;
  const AngularWeight weight_;
};

struct CostCase {
  std::string model;
  std::vector<double> params;
  int width;
  int height;
};

std::vector<CostCase> CostCases() {
  return {
      {"EQUIRECTANGULAR", {2000, 1000}, 2000, 1000},
      {"EUCM", {300, 310, 500, 400, 0.6, 1.1}, 1000, 800},
      {"UNIFIED_OMNI",
       {300, 310, 500, 400, 1.1, -0.02, 0.005, 0.0005, -0.0005},
       1000,
       800},
      {"DOUBLE_SPHERE", {300, 310, 500, 400, -0.2, 0.6}, 1000, 800},
      // Kannala-Brandt over its whole field (no focal prior: spherical).
      {"OPENCV_FISHEYE",
       {300, 305, 500, 400, -0.012, 0.0016, -0.0002, 0.00001},
       1000,
       800},
  };
}

void PrintTo(const CostCase& cost_case, std::ostream* os) {
  *os << cost_case.model;
}

// Evaluates `cost` at `parameters`, asking for the Jacobians of the blocks
// whose bit is set in `mask`; the Jacobians of the other blocks stay empty.
struct Evaluation {
  bool ok = false;
  double residuals[2] = {0, 0};
  std::vector<std::vector<double>> jacobians;
};

Evaluation Evaluate(const ceres::CostFunction& cost,
                    const std::vector<const double*>& parameters,
                    int mask) {
  Evaluation evaluation;
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  evaluation.jacobians.resize(sizes.size());
  std::vector<double*> jacobians(sizes.size(), nullptr);
  for (size_t i = 0; i < sizes.size(); ++i) {
    if (mask & (1 << i)) {
      evaluation.jacobians[i].assign(2 * sizes[i], 0.0);
      jacobians[i] = evaluation.jacobians[i].data();
    }
  }
  evaluation.ok = cost.Evaluate(
      parameters.data(), evaluation.residuals, mask ? jacobians.data() : nullptr);
  return evaluation;
}

void ExpectSameEvaluation(const Evaluation& analytic,
                          const Evaluation& reference,
                          const std::string& what) {
  ASSERT_EQ(analytic.ok, reference.ok) << what;
  if (!reference.ok) return;
  for (int row = 0; row < 2; ++row) {
    EXPECT_NEAR(analytic.residuals[row],
                reference.residuals[row],
                1e-9 * (1 + std::abs(reference.residuals[row])))
        << what;
  }
  for (size_t block = 0; block < reference.jacobians.size(); ++block) {
    ASSERT_EQ(analytic.jacobians[block].size(),
              reference.jacobians[block].size());
    for (size_t i = 0; i < reference.jacobians[block].size(); ++i) {
      EXPECT_NEAR(analytic.jacobians[block][i],
                  reference.jacobians[block][i],
                  1e-7 * (1 + std::abs(reference.jacobians[block][i])))
          << what << " block " << block << " entry " << i;
    }
  }
}

// Observations of random points at angles from the optical axis up to the
// lens's reach (beyond 90 degrees: behind the image plane), each observed at
// the projection of a slightly displaced point (non-zero residual) or at its
// exact projection (zero residual).
class SphereCostFunction : public ::testing::TestWithParam<CostCase> {
 protected:
  struct Observation {
    Eigen::Vector2d pixel;
    Eigen::Vector3d point3D;
  };

  std::vector<Observation> Observations(const Camera& camera,
                                        const Rigid3d& cam_from_world,
                                        std::mt19937* rng) const {
    // Every third point beyond 90 degrees from the axis (up to 100 for the
    // fisheye lenses, all around for the panorama).
    const double max_angle =
        camera.model_id == CameraModelId::kEquirectangular ? kPi
                                                           : 100 * kPi / 180;
    std::uniform_real_distribution<double> angle(0, max_angle);
    std::uniform_real_distribution<double> behind_angle(kPi / 2, max_angle);
    std::uniform_real_distribution<double> azimuth(-kPi, kPi);
    std::uniform_real_distribution<double> depth(0.5, 20);
    std::normal_distribution<double> noise(0, 0.02);
    const Rigid3d world_from_cam = Inverse(cam_from_world);
    std::vector<Observation> observations;
    while (observations.size() < 60) {
      const double a =
          observations.size() % 3 == 1 ? behind_angle(*rng) : angle(*rng);
      const double b = azimuth(*rng);
      const Eigen::Vector3d ray(
          std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a));
      const Eigen::Vector3d in_cam = depth(*rng) * ray;
      const Eigen::Vector3d displaced =
          observations.size() % 5 == 0
              ? in_cam
              : Eigen::Vector3d(in_cam + Eigen::Vector3d(noise(*rng),
                                                         noise(*rng),
                                                         noise(*rng)));
      const std::optional<Eigen::Vector2d> pixel =
          camera.ImgFromCam(displaced, /*check_cheirality=*/false);
      if (!pixel || pixel->x() < 0 || pixel->y() < 0 ||
          pixel->x() > camera.width || pixel->y() > camera.height) {
        continue;
      }
      observations.push_back({*pixel, world_from_cam * in_cam});
    }
    return observations;
  }

  Camera MakeCamera() const {
    const CostCase& cost_case = GetParam();
    Camera camera;
    camera.camera_id = 1;
    camera.model_id = CameraModelNameToId(cost_case.model);
    camera.params = cost_case.params;
    camera.width = cost_case.width;
    camera.height = cost_case.height;
    return camera;
  }
};

TEST_P(SphereCostFunction, AnalyticMatchesAutoDiff) {
  const Camera camera = MakeCamera();
  std::mt19937 rng(7);
  const Rigid3d cam_from_world(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3)
                                                    .normalized())),
      Eigen::Vector3d(0.3, -1.2, 2.0));
  int num_behind = 0;
  for (const auto& observation : Observations(camera, cam_from_world, &rng)) {
    num_behind += (cam_from_world * observation.point3D).z() < 0;
    std::unique_ptr<ceres::CostFunction> analytic(
        CreateSphereCameraCostFunction<ReprojErrorCostFunctor>(
            SphereResidualType::ANGULAR, camera, observation.pixel));
    std::unique_ptr<ceres::CostFunction> reference(
        CreateCameraCostFunction<AngularReprojErrorCostFunctor>(
            camera.model_id, camera.params.data(), observation.pixel));
    EXPECT_NE(typeid(*analytic), typeid(*reference));
    const std::vector<const double*> parameters = {
        observation.point3D.data(),
        cam_from_world.params.data(),
        camera.params.data()};
    for (int mask = 0; mask < 8; ++mask) {
      ExpectSameEvaluation(Evaluate(*analytic, parameters, mask),
                           Evaluate(*reference, parameters, mask),
                           "full, mask " + std::to_string(mask));
    }

    std::unique_ptr<ceres::CostFunction> analytic_constant_pose(
        CreateSphereCameraCostFunction<ReprojErrorConstantPoseCostFunctor>(
            SphereResidualType::ANGULAR,
            camera,
            observation.pixel,
            cam_from_world));
    // Reference: the autodiff functor with the pose block not asked for.
    const std::vector<const double*> constant_pose_parameters = {
        observation.point3D.data(), camera.params.data()};
    for (int mask = 0; mask < 4; ++mask) {
      Evaluation reference_evaluation =
          Evaluate(*reference, parameters, (mask & 1) | ((mask & 2) << 1));
      reference_evaluation.jacobians = {reference_evaluation.jacobians[0],
                                        reference_evaluation.jacobians[2]};
      ExpectSameEvaluation(
          Evaluate(*analytic_constant_pose, constant_pose_parameters, mask),
          reference_evaluation,
          "constant pose, mask " + std::to_string(mask));
    }
  }
  if (camera.model_id != CameraModelId::kEquirectangular) {
    EXPECT_GT(num_behind, 5) << "no rays behind the image plane were tested";
  }
}

TEST_P(SphereCostFunction, RigAnalyticMatchesAutoDiff) {
  const Camera camera = MakeCamera();
  std::mt19937 rng(11);
  const Rigid3d rig_from_world(
      Eigen::Quaterniond(Eigen::AngleAxisd(-0.4, Eigen::Vector3d(2, -1, 1)
                                                     .normalized())),
      Eigen::Vector3d(-0.5, 0.8, 1.5));
  // A lens turned well away from the reference and 4 cm off it.
  const Rigid3d cam_from_rig(
      Eigen::Quaterniond(Eigen::AngleAxisd(2.5, Eigen::Vector3d(0.1, 1, 0.2)
                                                    .normalized())),
      Eigen::Vector3d(0.03, -0.01, 0.025));
  const Rigid3d cam_from_world = cam_from_rig * rig_from_world;
  int num_behind = 0;
  for (const auto& observation : Observations(camera, cam_from_world, &rng)) {
    num_behind += (cam_from_world * observation.point3D).z() < 0;
    std::unique_ptr<ceres::CostFunction> analytic(
        CreateSphereCameraCostFunction<RigReprojErrorCostFunctor>(
            SphereResidualType::ANGULAR, camera, observation.pixel));
    std::unique_ptr<ceres::CostFunction> reference(
        CreateCameraCostFunction<AngularRigReprojErrorCostFunctor>(
            camera.model_id, camera.params.data(), observation.pixel));
    EXPECT_NE(typeid(*analytic), typeid(*reference));
    const std::vector<const double*> parameters = {
        observation.point3D.data(),
        cam_from_rig.params.data(),
        rig_from_world.params.data(),
        camera.params.data()};
    for (int mask = 0; mask < 16; ++mask) {
      ExpectSameEvaluation(Evaluate(*analytic, parameters, mask),
                           Evaluate(*reference, parameters, mask),
                           "rig, mask " + std::to_string(mask));
    }

    std::unique_ptr<ceres::CostFunction> analytic_constant_rig(
        CreateSphereCameraCostFunction<RigReprojErrorConstantRigCostFunctor>(
            SphereResidualType::ANGULAR,
            camera,
            observation.pixel,
            cam_from_rig));
    // Reference: the autodiff rig functor with cam_from_rig not asked for.
    const std::vector<const double*> constant_rig_parameters = {
        observation.point3D.data(),
        rig_from_world.params.data(),
        camera.params.data()};
    for (int mask = 0; mask < 8; ++mask) {
      Evaluation reference_evaluation =
          Evaluate(*reference, parameters, (mask & 1) | ((mask & 6) << 1));
      reference_evaluation.jacobians = {reference_evaluation.jacobians[0],
                                        reference_evaluation.jacobians[2],
                                        reference_evaluation.jacobians[3]};
      ExpectSameEvaluation(
          Evaluate(*analytic_constant_rig, constant_rig_parameters, mask),
          reference_evaluation,
          "constant rig, mask " + std::to_string(mask));
    }
  }
  if (camera.model_id != CameraModelId::kEquirectangular) {
    EXPECT_GT(num_behind, 5) << "no rays behind the image plane were tested";
  }
}

TEST_P(SphereCostFunction, PixelOutsideTheImageIsRefusedLikeAutoDiff) {
  const Camera camera = MakeCamera();
  const Eigen::Vector2d outside(-5.0, camera.height + 5.0);
  const Eigen::Vector3d point3D(0.1, 0.2, 3.0);
  const Rigid3d cam_from_world;
  std::unique_ptr<ceres::CostFunction> analytic(
      CreateSphereCameraCostFunction<ReprojErrorCostFunctor>(
          SphereResidualType::ANGULAR, camera, outside));
  std::unique_ptr<ceres::CostFunction> reference(
      CreateCameraCostFunction<AngularReprojErrorCostFunctor>(
          camera.model_id, camera.params.data(), outside));
  const std::vector<const double*> parameters = {
      point3D.data(), cam_from_world.params.data(), camera.params.data()};
  const Evaluation analytic_evaluation = Evaluate(*analytic, parameters, 7);
  const Evaluation reference_evaluation = Evaluate(*reference, parameters, 7);
  EXPECT_EQ(analytic_evaluation.ok, reference_evaluation.ok);
  if (camera.model_id == CameraModelId::kEquirectangular) {
    EXPECT_FALSE(analytic_evaluation.ok);
  }
}

// The camera-parameter Jacobian (last block) of COST at PARAMETERS against
// central differences of COST's own residual.
void ExpectParamsJacobianIsTheDerivative(
    const ceres::CostFunction& cost,
    std::vector<const double*> parameters,
    const std::string& what) {
  const size_t last = parameters.size() - 1;
  const int num_params = cost.parameter_block_sizes()[last];
  const Evaluation evaluation =
      Evaluate(cost, parameters, 1 << static_cast<int>(last));
  ASSERT_TRUE(evaluation.ok) << what;
  std::vector<double> params(parameters[last], parameters[last] + num_params);
  parameters[last] = params.data();
  for (int i = 0; i < num_params; ++i) {
    const double value = params[i];
    const double step = 1e-6 * (1 + std::abs(value));
    params[i] = value + step;
    const Evaluation plus = Evaluate(cost, parameters, 0);
    params[i] = value - step;
    const Evaluation minus = Evaluate(cost, parameters, 0);
    params[i] = value;
    ASSERT_TRUE(plus.ok && minus.ok) << what;
    for (int row = 0; row < 2; ++row) {
      const double numeric =
          (plus.residuals[row] - minus.residuals[row]) / (2 * step);
      EXPECT_NEAR(evaluation.jacobians[last][row * num_params + i],
                  numeric,
                  1e-5 * (1 + std::abs(numeric)))
          << what << " parameter " << i << " row " << row;
    }
  }
}

TEST_P(SphereCostFunction, ParamsJacobianIsTheDerivativeOfTheCost) {
  const Camera camera = MakeCamera();
  std::mt19937 rng(13);
  const Rigid3d rig_from_world(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, -1, 2)
                                                    .normalized())),
      Eigen::Vector3d(0.2, 0.4, -1.0));
  const Rigid3d cam_from_rig(
      Eigen::Quaterniond(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d(0, 0, -0.03));
  const Rigid3d cam_from_world = cam_from_rig * rig_from_world;
  int num_with_error = 0;
  for (const auto& observation : Observations(camera, cam_from_world, &rng)) {
    std::unique_ptr<ceres::CostFunction> single(
        CreateSphereCameraCostFunction<ReprojErrorCostFunctor>(
            SphereResidualType::ANGULAR, camera, observation.pixel));
    const std::vector<const double*> single_parameters = {
        observation.point3D.data(),
        cam_from_world.params.data(),
        camera.params.data()};
    const Evaluation evaluation = Evaluate(*single, single_parameters, 0);
    ASSERT_TRUE(evaluation.ok);
    num_with_error += std::hypot(evaluation.residuals[0],
                                 evaluation.residuals[1]) > 0.1;
    ExpectParamsJacobianIsTheDerivative(*single, single_parameters, "single");
    std::unique_ptr<ceres::CostFunction> rig(
        CreateSphereCameraCostFunction<RigReprojErrorCostFunctor>(
            SphereResidualType::ANGULAR, camera, observation.pixel));
    ExpectParamsJacobianIsTheDerivative(*rig,
                                        {observation.point3D.data(),
                                         cam_from_rig.params.data(),
                                         rig_from_world.params.data(),
                                         camera.params.data()},
                                        "rig");
  }
  // Most observations are off their point by a fraction of a degree: the
  // residual's unit would change their residual with the focal length.
  EXPECT_GT(num_with_error, 30);
}

// A direction ANGLE off the unit ray U, towards a random side.
Eigen::Vector3d OffTheRay(const Eigen::Vector3d& u,
                          double angle,
                          std::mt19937* rng) {
  Eigen::Vector3d e1, e2;
  sphera::RayTangentBasis(u, &e1, &e2);
  const double phi = std::uniform_real_distribution<double>(-kPi, kPi)(*rng);
  return std::cos(angle) * u +
         std::sin(angle) * (std::cos(phi) * e1 + std::sin(phi) * e2);
}

// The residual of COST (a single-image cost) for the point V seen from the
// origin through a camera of PARAMS.
Eigen::Vector2d ResidualAt(const ceres::CostFunction& cost,
                           const Eigen::Vector3d& v,
                           const std::vector<double>& params) {
  const Rigid3d cam_from_world;
  const Evaluation evaluation =
      Evaluate(cost, {v.data(), cam_from_world.params.data(), params.data()},
               0);
  EXPECT_TRUE(evaluation.ok);
  return Eigen::Vector2d(evaluation.residuals[0], evaluation.residuals[1]);
}

// The residual is the pixel residual to first order, direction included: a
// point a small angle off the observed ray gives the offset of its
// projection from the observed pixel, wherever the pixel lies (the rims
// compress the image radially unlike tangentially). EQUIRECTANGULAR is
// isotropic: the angle times its pixels per radian.
TEST_P(SphereCostFunction, ResidualIsThePixelOffsetToFirstOrder) {
  const Camera camera = MakeCamera();
  std::mt19937 rng(29);
  const bool isotropic = camera.model_id == CameraModelId::kEquirectangular;
  const double pixels_per_radian = 1.0 / camera.CamFromImgThreshold(1.0);
  constexpr double kAngle = 2e-4;
  int num_anisotropic = 0;
  for (const auto& observation : Observations(camera, Rigid3d(), &rng)) {
    // The observed ray (the camera is at the origin), and a point off it.
    const Eigen::Vector3d u = observation.point3D.normalized();
    const Eigen::Vector3d v = OffTheRay(u, kAngle, &rng);
    const std::optional<Eigen::Vector2d> observed =
        camera.ImgFromCam(u, /*check_cheirality=*/false);
    const std::optional<Eigen::Vector2d> moved =
        camera.ImgFromCam(v, /*check_cheirality=*/false);
    ASSERT_TRUE(observed.has_value() && moved.has_value());
    std::unique_ptr<ceres::CostFunction> cost(
        CreateSphereCameraCostFunction<ReprojErrorCostFunctor>(
            SphereResidualType::ANGULAR, camera, *observed));
    const Eigen::Vector2d residual = ResidualAt(*cost, v, camera.params);
    if (isotropic) {
      EXPECT_NEAR(residual.norm(), kAngle * pixels_per_radian,
                  1e-6 * pixels_per_radian);
      continue;
    }
    const Eigen::Vector2d offset = *moved - *observed;
    EXPECT_LT((residual - offset).norm(), 2e-3 * offset.norm())
        << "pixel " << observed->transpose() << " residual "
        << residual.transpose() << " offset " << offset.transpose();
    num_anisotropic += std::abs(residual.norm() / (kAngle * pixels_per_radian) -
                                1) > 0.05;
  }
  // Away from the axis the pixels per radian differ from the axis's.
  if (!isotropic) {
    EXPECT_GT(num_anisotropic, 10);
  }
}

// The metric follows the focal length being refined: made at one focal
// length and evaluated at one 5% longer, the residual is still the pixel
// offset through the camera as it now is (a fixed metric would be 5% short
// and let a longer focal length shrink every residual).
TEST_P(SphereCostFunction, ResidualFollowsTheFocalLength) {
  const Camera camera = MakeCamera();
  if (camera.model_id == CameraModelId::kEquirectangular) {
    return;  // no focal length
  }
  Camera longer = camera;
  for (const size_t idx : camera.FocalLengthIdxs()) {
    longer.params[idx] *= 1.05;
  }
  std::mt19937 rng(31);
  constexpr double kAngle = 2e-4;
  for (const auto& observation : Observations(camera, Rigid3d(), &rng)) {
    const std::optional<Eigen::Vector2d> pixel =
        camera.ImgFromCam(observation.point3D, /*check_cheirality=*/false);
    ASSERT_TRUE(pixel.has_value());
    std::unique_ptr<ceres::CostFunction> cost(
        CreateSphereCameraCostFunction<ReprojErrorCostFunctor>(
            SphereResidualType::ANGULAR, camera, *pixel));
    // The pixel's ray through the longer lens, and a point off it.
    const std::optional<Eigen::Vector3d> ray = longer.CamRayFromImg(*pixel);
    if (!ray) continue;
    const Eigen::Vector3d v = OffTheRay(ray->normalized(), kAngle, &rng);
    const std::optional<Eigen::Vector2d> moved =
        longer.ImgFromCam(v, /*check_cheirality=*/false);
    ASSERT_TRUE(moved.has_value());
    const Eigen::Vector2d residual = ResidualAt(*cost, v, longer.params);
    const Eigen::Vector2d offset = *moved - *pixel;
    EXPECT_LT((residual - offset).norm(), 0.02 * offset.norm())
        << "pixel " << pixel->transpose() << " residual "
        << residual.transpose() << " offset " << offset.transpose();
  }
}

TEST(AngularResidualWeight, NonFiniteMetricTakesTheIsotropicScale) {
  // A lens whose self-calibration ran away to an infinite focal length:
  // every pixel still lifts (to the axis), but the camera's metric there is
  // not finite. The weight takes the one scale instead of an SVD of that
  // matrix, which need not return (the point filter hung on it).
  using Model = UnifiedOmniCameraModel;
  using SphereModel = typename SphereMathOf<Model>::type;
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> params = {inf, inf, 512, 512, 1.2, 0, 0, 0, 0};
  const double pixel[2] = {700, 300};
  double ray[3];
  ASSERT_TRUE(SphereModel::RayFromImage(params.data(), pixel, ray));
  Eigen::Matrix<double, 2, 2, Eigen::RowMajor> metric;
  ASSERT_TRUE(sphera::PixelFromTangentAtRay<SphereModel>(
      params.data(), ray, metric.data()));
  ASSERT_FALSE(metric.allFinite());
  const AngularWeight weight = AngularResidualWeight<Model>(
      params.data(), Eigen::Vector2d(pixel[0], pixel[1]));
  EXPECT_TRUE(weight.isotropic);
}

INSTANTIATE_TEST_SUITE_P(SphereModels,
                         SphereCostFunction,
                         ::testing::ValuesIn(CostCases()));

}  // namespace
}  // namespace colmap
