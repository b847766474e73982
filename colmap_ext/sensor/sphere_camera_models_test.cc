// SPHERA's spherical fisheye models seen through COLMAP 4.x's own camera API:
// ids and names as files store them, rays beyond a hemisphere in both
// directions, the analytic Jacobian that bundle adjustment uses, rescaling,
// parameter checks and the pixel scale of reprojection errors; upstream's
// OPENCV_FISHEYE and THIN_PRISM_FISHEYE pixels in front of the image plane.
#include "colmap/estimators/cost_functions/reprojection_error.h"
#include "colmap/scene/camera.h"
#include "colmap/scene/projection.h"
#include "colmap/sensor/models.h"

#include <cmath>
#include <memory>
#include <sstream>

#include <gtest/gtest.h>

namespace colmap {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct ModelCase {
  std::string name;
  int id;
  std::vector<double> params;
  // Largest angle from the optical axis (+z) sampled; beyond pi/2 the rays
  // point behind the image plane.
  double max_angle_from_axis;
  // fx = fy (0: a model without a focal length).
  double focal_length = 300;
};

std::vector<ModelCase> SphereModelCases() {
  return {
      {"EUCM", 16, {300, 300, 500, 400, 0.6, 1.1}, 100.0 / 180.0 * kPi},
      {"UNIFIED_OMNI",
       64,
       {300, 300, 500, 400, 1.1, -0.02, 0.005, 0.0005, -0.0005},
       95.0 / 180.0 * kPi},
      {"DOUBLE_SPHERE", 65, {300, 300, 500, 400, -0.2, 0.6}, 100.0 / 180.0 * kPi},
      {"OPENCV_FISHEYE",
       5,
       {300, 300, 500, 400, 0.02, -0.003, 0.0004, -0.00002},
       100.0 / 180.0 * kPi},
      {"THIN_PRISM_FISHEYE",
       10,
       {300, 300, 500, 400, 0.02, -0.003, 0.0005, -0.0003, 0.0004, -0.00002,
        0.0004, -0.0002},
       100.0 / 180.0 * kPi},
      // Folds at 111 degrees from the axis.
      {"OCAM",
       66,
       {500, 400, 1, 0, 0, -300, 1.25e-3, -6e-7, 0},
       100.0 / 180.0 * kPi,
       0},
  };
}

void PrintTo(const ModelCase& model_case, std::ostream* os) {
  *os << model_case.name;
}

Camera MakeCamera(const ModelCase& model_case) {
  Camera camera;
  camera.camera_id = 1;
  camera.model_id = CameraModelNameToId(model_case.name);
  camera.params = model_case.params;
  camera.width = 1000;
  camera.height = 800;
  return camera;
}

class SphereCameraModel : public ::testing::TestWithParam<ModelCase> {};

TEST_P(SphereCameraModel, IdNameAndTaxonomy) {
  const ModelCase& model_case = GetParam();
  ASSERT_TRUE(ExistsCameraModelWithName(model_case.name));
  const CameraModelId model_id = CameraModelNameToId(model_case.name);
  EXPECT_EQ(static_cast<int>(model_id), model_case.id);
  EXPECT_TRUE(ExistsCameraModelWithId(model_id));
  EXPECT_EQ(CameraModelIdToName(model_id), model_case.name);
  std::ostringstream stream;
  stream << model_id;
  EXPECT_EQ(stream.str(), model_case.name);
  EXPECT_EQ(CameraModelNumParams(model_id), model_case.params.size());

  const Camera camera = MakeCamera(model_case);
  EXPECT_TRUE(camera.IsSpherical());
  EXPECT_FALSE(camera.IsPerspective());
  EXPECT_FALSE(camera.IsPerspectivePinhole());
  EXPECT_FALSE(camera.IsPerspectiveFisheye());
  const size_t num_focal = model_case.focal_length > 0 ? 2 : 0;
  EXPECT_EQ(camera.FocalLengthIdxs().size(), num_focal);
  EXPECT_EQ(camera.PrincipalPointIdxs().size(), 2u);
  EXPECT_EQ(camera.ExtraParamsIdxs().size(),
            model_case.params.size() - 2 - num_focal);
  EXPECT_TRUE(camera.MetaDataParamsIdxs().empty());
  EXPECT_DOUBLE_EQ(camera.MeanFocalLength(), model_case.focal_length);
  EXPECT_FALSE(camera.HasBogusParams(0.1, 10, 1));
}

TEST_P(SphereCameraModel, RaysBeyondTheHemisphereRoundTrip) {
  const ModelCase& model_case = GetParam();
  const Camera camera = MakeCamera(model_case);
  int num_behind = 0;
  for (double polar = 0; polar <= model_case.max_angle_from_axis;
       polar += model_case.max_angle_from_axis / 16) {
    for (double azimuth = -kPi; azimuth < kPi; azimuth += kPi / 8) {
      const Eigen::Vector3d ray(std::sin(polar) * std::cos(azimuth),
                                std::sin(polar) * std::sin(azimuth),
                                std::cos(polar));
      const std::optional<Eigen::Vector2d> pixel = camera.ImgFromCam(ray);
      ASSERT_TRUE(pixel.has_value()) << "polar " << polar;
      const std::optional<Eigen::Vector3d> ray_back =
          camera.CamRayFromImg(*pixel);
      ASSERT_TRUE(ray_back.has_value()) << "polar " << polar;
      EXPECT_NEAR(ray_back->norm(), 1.0, 1e-12);
      EXPECT_LT((*ray_back - ray).norm(), 1e-7) << "polar " << polar;
      num_behind += ray.z() < 0;
    }
  }
  EXPECT_GT(num_behind, 0);
  // The normalized-plane lifting stops at the image plane.
  const std::optional<Eigen::Vector2d> behind_pixel =
      camera.ImgFromCam(Eigen::Vector3d(1, 0, -0.05));
  ASSERT_TRUE(behind_pixel.has_value());
  EXPECT_FALSE(camera.CamFromImg(*behind_pixel).has_value());
  // Straight backwards is outside every one of these fields of view.
  EXPECT_FALSE(camera.ImgFromCam(Eigen::Vector3d(0, 0, -1)).has_value());
}

TEST_P(SphereCameraModel, AnalyticJacobianMatchesFiniteDifferences) {
  const ModelCase& model_case = GetParam();
  const Camera camera = MakeCamera(model_case);
  const Eigen::Vector3d point(0.7, -0.4, -0.1);
  Eigen::Matrix2x3d J_uvw;
  const std::optional<Eigen::Vector2d> pixel =
      camera.ImgFromCamWithJac(point, &J_uvw);
  ASSERT_TRUE(pixel.has_value());
  EXPECT_LT((*pixel - *camera.ImgFromCam(point)).norm(), 1e-12);
  const double step = 1e-6;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d forward = point;
    Eigen::Vector3d backward = point;
    forward[i] += step;
    backward[i] -= step;
    const Eigen::Vector2d numeric =
        (*camera.ImgFromCam(forward) - *camera.ImgFromCam(backward)) /
        (2 * step);
    EXPECT_LT((numeric - J_uvw.col(i)).norm(), 1e-4) << "coordinate " << i;
  }
}

TEST_P(SphereCameraModel, BundleAdjustmentCostIsThePixelResidual) {
  const ModelCase& model_case = GetParam();
  Camera camera = MakeCamera(model_case);
  const Eigen::Vector3d point_in_world(0.7, -0.4, -0.1);
  const Eigen::Vector2d observed =
      *camera.ImgFromCam(point_in_world) + Eigen::Vector2d(0.5, -0.25);
  std::unique_ptr<ceres::CostFunction> cost(
      CreateCameraCostFunction<ReprojErrorCostFunctor>(camera.model_id,
                                                       observed));
  ASSERT_NE(cost, nullptr);
  // Identity pose: quaternion (x, y, z, w) and translation.
  const double cam_from_world[7] = {0, 0, 0, 1, 0, 0, 0};
  const double* parameters[3] = {
      point_in_world.data(), cam_from_world, camera.params.data()};
  double residuals[2];
  ASSERT_TRUE(cost->Evaluate(parameters, residuals, nullptr));
  EXPECT_NEAR(residuals[0], -0.5, 1e-9);
  EXPECT_NEAR(residuals[1], 0.25, 1e-9);
}

TEST_P(SphereCameraModel, RescaleScalesEveryPixel) {
  const ModelCase& model_case = GetParam();
  const Camera original = MakeCamera(model_case);
  Camera camera = original;
  camera.Rescale(0.5);
  EXPECT_EQ(camera.width, 500u);
  EXPECT_EQ(camera.height, 400u);
  for (const Eigen::Vector3d& ray : {Eigen::Vector3d(0.1, -0.2, 1),
                                     Eigen::Vector3d(1, 0.5, -0.1)}) {
    EXPECT_LT((*camera.ImgFromCam(ray) - 0.5 * *original.ImgFromCam(ray))
                  .norm(),
              1e-7);
  }
  if (model_case.focal_length == 0) {
    return;
  }
  // Focal length and principal point only.
  EXPECT_DOUBLE_EQ(camera.params[0], 150);
  EXPECT_DOUBLE_EQ(camera.params[1], 150);
  EXPECT_DOUBLE_EQ(camera.params[2], 250);
  EXPECT_DOUBLE_EQ(camera.params[3], 200);
  for (size_t i = 4; i < camera.params.size(); ++i) {
    EXPECT_EQ(camera.params[i], model_case.params[i]);
  }
}

TEST_P(SphereCameraModel, ReprojectionErrorIsThePixelDistance) {
  const ModelCase& model_case = GetParam();
  const Camera camera = MakeCamera(model_case);
  const double angle = 0.002;
  // A point behind the image plane, observed 0.002 rad away from its ray:
  // its error is the pixel distance of the two rays' projections (to first
  // order), not the angle at the pixels per radian of the image centre.
  const Eigen::Vector3d ray = Eigen::Vector3d(1, 0.2, -0.3).normalized();
  const Eigen::Vector3d axis = ray.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d observed_ray = Eigen::AngleAxisd(angle, axis) * ray;
  const Eigen::Vector2d observed = *camera.ImgFromCam(observed_ray);
  const double distance = (*camera.ImgFromCam(ray) - observed).norm();
  const double squared_error = CalculateSquaredReprojectionError(
      observed, 5.0 * ray, Rigid3d(), camera);
  EXPECT_NEAR(std::sqrt(squared_error), distance, 0.01 * distance);
  // The model's scale at the image centre (pixels per radian of a small
  // rotation of the optical axis) is what thresholds in pixels become in
  // angles.
  const double pixels_per_radian = 1.0 / camera.CamFromImgThreshold(1.0);
  const double delta = 1e-6;
  const Eigen::Vector2d centre = *camera.ImgFromCam(Eigen::Vector3d::UnitZ());
  const Eigen::Vector2d off_axis = *camera.ImgFromCam(
      Eigen::Vector3d(std::sin(delta), 0, std::cos(delta)));
  EXPECT_NEAR(pixels_per_radian, (off_axis - centre).norm() / delta,
              1e-3 * pixels_per_radian);
}

INSTANTIATE_TEST_SUITE_P(SphereModels,
                         SphereCameraModel,
                         ::testing::ValuesIn(SphereModelCases()));

TEST(SphereCameraModels, BogusParametersAreReported) {
  Camera camera = Camera::CreateFromModelName(1, "EUCM", 300, 1000, 800);
  camera.params[4] = 1.5;  // alpha outside [0, 1]
  EXPECT_TRUE(camera.HasBogusParams(0.1, 10, 1));
  camera = Camera::CreateFromModelName(1, "UNIFIED_OMNI", 300, 1000, 800);
  camera.params[0] = -300;
  EXPECT_TRUE(camera.HasBogusParams(0.1, 10, 1));
}

// In front of the image plane SPHERA's OPENCV_FISHEYE and THIN_PRISM_FISHEYE
// are upstream's models (whose structs models.h still holds): the same pixel
// of every ray and the same normalized point of every pixel.
template <typename UpstreamModel>
void ExpectUpstreamInFront(const std::vector<double>& params) {
  const CameraModelId model_id = UpstreamModel::model_id;
  EXPECT_TRUE(CameraModelIsSpherical(model_id));
  for (double polar = 0; polar < 85.0 / 180 * kPi; polar += 5.0 / 180 * kPi) {
    for (double azimuth = -kPi; azimuth < kPi; azimuth += kPi / 7) {
      const Eigen::Vector3d ray(std::sin(polar) * std::cos(azimuth),
                                std::sin(polar) * std::sin(azimuth),
                                std::cos(polar));
      double x, y, upstream_x, upstream_y;
      ASSERT_TRUE(UpstreamModel::ImgFromCam(params.data(), ray.x(), ray.y(),
                                            ray.z(), &upstream_x, &upstream_y));
      const std::optional<Eigen::Vector2d> pixel =
          CameraModelImgFromCam(model_id, params, ray);
      ASSERT_TRUE(pixel.has_value()) << polar;
      x = pixel->x();
      y = pixel->y();
      EXPECT_NEAR(x, upstream_x, 1e-8) << polar;
      EXPECT_NEAR(y, upstream_y, 1e-8) << polar;
      double u, v;
      ASSERT_TRUE(UpstreamModel::CamFromImg(params.data(), x, y, &u, &v));
      const std::optional<Eigen::Vector2d> normalized =
          CameraModelCamFromImg(model_id, params, Eigen::Vector2d(x, y));
      ASSERT_TRUE(normalized.has_value()) << polar;
      EXPECT_NEAR(normalized->x(), u, 1e-8 * (1 + std::abs(u))) << polar;
      EXPECT_NEAR(normalized->y(), v, 1e-8 * (1 + std::abs(v))) << polar;
    }
  }
  EXPECT_EQ(CameraModelParamsInfo(model_id),
            UpstreamModel::InitializeParamsInfo());
}

TEST(SphereCameraModels, KannalaBrandtIsUpstreamsInFrontOfTheImagePlane) {
  ExpectUpstreamInFront<OpenCVFisheyeCameraModel>(
      {300, 310, 500, 400, 0.02, -0.003, 0.0004, -0.00002});
  ExpectUpstreamInFront<ThinPrismFisheyeCameraModel>(
      {300, 310, 500, 400, 0.02, -0.003, 0.0005, -0.0003, 0.0004, -0.00002,
       0.0004, -0.0002});
}

TEST(SphereCameraModels, UpstreamIdsKeepTheirNames) {
  std::ostringstream stream;
  stream << CameraModelId::kEquirectangular << ' ' << CameraModelId::kPinhole
         << ' ' << static_cast<CameraModelId>(40);
  EXPECT_EQ(stream.str(), "EQUIRECTANGULAR PINHOLE 40");
  EXPECT_FALSE(ExistsCameraModelWithId(static_cast<CameraModelId>(40)));
  const Camera equirect =
      Camera::CreateFromModelName(1, "EQUIRECTANGULAR", 0, 2048, 1024);
  EXPECT_EQ(equirect.MeanFocalLength(), 0.0);
  EXPECT_TRUE(equirect.FocalLengthIdxs().empty());
}

}  // namespace
}  // namespace colmap
