// The COLMAP side of the camera models: every model, COLMAP's own eleven
// included, lifts pixels to unit rays and projects rays back through the
// colmap::Camera API, with an explicit "not visible" result.
#include "camera_models/registry.h"
#include "colmap/scene/camera.h"
#include "colmap/sensor/models.h"

#include <cmath>

#include <gtest/gtest.h>

namespace colmap {
namespace {

constexpr double kPi = 3.14159265358979323846;

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

struct ModelCase {
  std::string name;
  std::vector<double> params;
  size_t width;
  size_t height;
  // Largest angle from the optical axis (+z) that the test samples.
  double max_angle_from_axis;
};

std::vector<ModelCase> AllModelCases() {
  const size_t w = 1000;
  const size_t h = 800;
  return {
      {"SIMPLE_PINHOLE", {500, 500, 400}, w, h, 0.7},
      {"PINHOLE", {500, 520, 500, 400}, w, h, 0.7},
      {"SIMPLE_RADIAL", {500, 500, 400, 0.01}, w, h, 0.6},
      {"RADIAL", {500, 500, 400, 0.01, -0.005}, w, h, 0.6},
      {"OPENCV", {500, 520, 500, 400, 0.01, -0.005, 0.001, -0.001}, w, h, 0.6},
      {"OPENCV_FISHEYE", {300, 300, 500, 400, 0.01, 0.001, 0, 0}, w, h, 1.2},
      {"FULL_OPENCV",
       {500, 520, 500, 400, 0.01, -0.005, 0.001, -0.001, 0, 0, 0, 0}, w, h, 0.6},
      {"FOV", {500, 520, 500, 400, 0.3}, w, h, 0.7},
      {"SIMPLE_RADIAL_FISHEYE", {300, 500, 400, 0.01}, w, h, 1.2},
      {"RADIAL_FISHEYE", {300, 500, 400, 0.01, 0.001}, w, h, 1.2},
      {"THIN_PRISM_FISHEYE",
       {300, 310, 500, 400, 0.01, 0.001, 0, 0, 0, 0, 0, 0}, w, h, 1.2},
      {"EUCM", {300, 300, 500, 400, 0.6, 1.1}, w, h, 1.6},
      {"EQUIRECTANGULAR", {2048, 1024}, 2048, 1024, kPi},
      {"UNIFIED_OMNI", {300, 300, 500, 400, 1.1, -0.02, 0.005, 0.0005, -0.0005},
       w, h, 95.0 / 180.0 * kPi},
      {"DOUBLE_SPHERE", {300, 300, 500, 400, -0.2, 0.6}, w, h, 1.6},
  };
}

void PrintTo(const ModelCase& model_case, std::ostream* os) {
  *os << model_case.name;
}

class CameraModelRays : public ::testing::TestWithParam<ModelCase> {};

TEST_P(CameraModelRays, RayPixelRayRoundTrip) {
  const ModelCase& model_case = GetParam();
  ASSERT_TRUE(ExistsCameraModelWithName(model_case.name));
  Camera camera;
  camera.model_id = CameraModelNameToId(model_case.name);
  camera.params = model_case.params;
  camera.width = model_case.width;
  camera.height = model_case.height;
  ASSERT_EQ(camera.ParamsError(), "") << model_case.name;

  int num_checked = 0;
  for (double polar = 0; polar <= model_case.max_angle_from_axis;
       polar += model_case.max_angle_from_axis / 20) {
    for (double azimuth = -kPi; azimuth < kPi; azimuth += kPi / 12) {
      const Eigen::Vector3d ray(std::sin(polar) * std::cos(azimuth),
                                std::sin(polar) * std::sin(azimuth),
                                std::cos(polar));
      Eigen::Vector2d pixel;
      ASSERT_TRUE(camera.ImgFromCamRay(ray, &pixel))
          << model_case.name << " polar " << polar;
      Eigen::Vector3d lifted;
      ASSERT_TRUE(camera.CamRayFromImg(pixel, &lifted)) << model_case.name;
      EXPECT_NEAR(lifted.norm(), 1.0, 1e-12);
      EXPECT_LT(AngleBetween(ray, lifted), 1e-8)
          << model_case.name << " polar " << polar << " azimuth " << azimuth;
      ++num_checked;
    }
  }
  EXPECT_GT(num_checked, 200);
}

TEST_P(CameraModelRays, PixelToAngleMatchesNeighbouringRays) {
  const ModelCase& model_case = GetParam();
  Camera camera;
  camera.model_id = CameraModelNameToId(model_case.name);
  camera.params = model_case.params;
  camera.width = model_case.width;
  camera.height = model_case.height;
  // One pixel to the right of the image centre spans PixelToAngle radians.
  const Eigen::Vector2d center(model_case.width / 2.0,
                               model_case.height / 2.0);
  Eigen::Vector3d ray1;
  Eigen::Vector3d ray2;
  ASSERT_TRUE(camera.CamRayFromImg(center, &ray1));
  ASSERT_TRUE(camera.CamRayFromImg(center + Eigen::Vector2d(1, 0), &ray2));
  EXPECT_NEAR(camera.CamRayFromImgThreshold(1.0), AngleBetween(ray1, ray2),
              0.05 * AngleBetween(ray1, ray2))
      << model_case.name;
}

INSTANTIATE_TEST_SUITE_P(
    AllModels,
    CameraModelRays,
    ::testing::ValuesIn(AllModelCases()),
    [](const ::testing::TestParamInfo<ModelCase>& info) {
      return info.param.name;
    });

TEST(CameraModelRays, PlaneModelsReportRaysBehindAsNotVisible) {
  Camera camera = Camera::CreateFromModelName(1, "PINHOLE", 500, 1000, 800);
  Eigen::Vector2d pixel;
  EXPECT_FALSE(camera.ImgFromCamRay(Eigen::Vector3d(0.1, 0.2, -1), &pixel));
  EXPECT_FALSE(camera.ImgFromCamRay(Eigen::Vector3d(1, 0, 0), &pixel));
  EXPECT_TRUE(camera.ImgFromCamRay(Eigen::Vector3d(0.1, 0.2, 1), &pixel));
}

TEST(CameraModelRays, SphereModelsSeeBehindTheImagePlane) {
  Camera panorama =
      Camera::CreateFromModelName(1, "EQUIRECTANGULAR", 0, 2048, 1024);
  Eigen::Vector2d pixel;
  ASSERT_TRUE(panorama.ImgFromCamRay(Eigen::Vector3d(0, 0, -1), &pixel));
  // Straight behind lies on the ±180° seam, at the horizon.
  EXPECT_NEAR(std::fmod(pixel.x(), 2048.0), 0.0, 1e-9);
  EXPECT_NEAR(pixel.y(), 512.0, 1e-9);

  Camera fisheye;
  fisheye.model_id = CameraModelNameToId("UNIFIED_OMNI");
  fisheye.params = {300, 300, 500, 400, 1.1, 0, 0, 0, 0};
  const double behind = 100.0 / 180.0 * kPi;
  EXPECT_TRUE(fisheye.ImgFromCamRay(
      Eigen::Vector3d(std::sin(behind * 0.9), 0, std::cos(behind * 0.9)),
      &pixel));
  EXPECT_FALSE(fisheye.ImgFromCamRay(Eigen::Vector3d(0, 0, -1), &pixel));
}

TEST(CameraModels, ModelIdsAndNamesMatchUpstreamAndDocs) {
  EXPECT_EQ(static_cast<int>(CameraModelNameToId("EUCM")), 16);
  EXPECT_EQ(static_cast<int>(CameraModelNameToId("EQUIRECTANGULAR")), 17);
  EXPECT_EQ(static_cast<int>(CameraModelNameToId("UNIFIED_OMNI")), 64);
  EXPECT_EQ(static_cast<int>(CameraModelNameToId("DOUBLE_SPHERE")), 65);
  EXPECT_EQ(CameraModelParamsInfo(CameraModelId::kEquirectangular), "w, h");
  EXPECT_EQ(CameraModelParamsInfo(CameraModelId::kEUCM),
            "fx, fy, cx, cy, alpha, beta");
  // COLMAP's own models keep their ids.
  EXPECT_EQ(static_cast<int>(CameraModelNameToId("THIN_PRISM_FISHEYE")), 10);
  for (const sphera::ModelInfo& info : sphera::SphereModels()) {
    EXPECT_EQ(CameraModelIdToName(static_cast<CameraModelId>(info.id)),
              info.name);
    EXPECT_EQ(CameraModelNumParams(static_cast<CameraModelId>(info.id)),
              static_cast<size_t>(info.num_params));
  }
}

TEST(CameraModels, InitializationFromImageSize) {
  const Camera panorama =
      Camera::CreateFromModelName(1, "EQUIRECTANGULAR", 1234.0, 5376, 2688);
  EXPECT_EQ(panorama.params, std::vector<double>({5376, 2688}));
  EXPECT_EQ(panorama.ParamsError(), "");
  EXPECT_EQ(panorama.FocalLengthIdxs().size(), 0u);
}

TEST(CameraModels, ParamsErrorNamesTheProblem) {
  Camera panorama =
      Camera::CreateFromModelName(1, "EQUIRECTANGULAR", 0, 5376, 2688);
  panorama.params = {4000, 2000};
  EXPECT_NE(panorama.ParamsError().find("5376x2688"), std::string::npos)
      << panorama.ParamsError();
  panorama.width = 5000;
  panorama.height = 2688;
  panorama.params = {5000, 2688};
  EXPECT_NE(panorama.ParamsError().find("twice"), std::string::npos)
      << panorama.ParamsError();
  panorama.params = {5376};
  EXPECT_NE(panorama.ParamsError().find("expects 2"), std::string::npos)
      << panorama.ParamsError();

  Camera pinhole = Camera::CreateFromModelName(1, "PINHOLE", 500, 1000, 800);
  EXPECT_EQ(pinhole.ParamsError(), "");
  pinhole.params[1] = std::nan("");
  EXPECT_NE(pinhole.ParamsError().find("finite"), std::string::npos);
  pinhole.params[1] = -3;
  EXPECT_NE(pinhole.ParamsError().find("focal"), std::string::npos);
}

TEST(CameraModels, FixedParamsOnlyForEquirectangular) {
  EXPECT_EQ(CameraModelFixedParamsIdxs(CameraModelId::kEquirectangular),
            std::vector<size_t>({0, 1}));
  EXPECT_TRUE(CameraModelFixedParamsIdxs(CameraModelId::kEUCM).empty());
  EXPECT_TRUE(CameraModelFixedParamsIdxs(CameraModelId::kPinhole).empty());
  EXPECT_TRUE(CameraModelIsSphere(CameraModelId::kDoubleSphere));
  EXPECT_FALSE(CameraModelIsSphere(CameraModelId::kOpenCVFisheye));
}

}  // namespace
}  // namespace colmap
