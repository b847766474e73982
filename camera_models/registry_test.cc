// Runtime dispatch and parameter validation.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "camera_models/registry.h"

namespace sphera {
namespace {

using ::testing::HasSubstr;

const std::vector<int> kAllIds = {1, 4, 16, 17, 64, 65};

std::vector<double> ValidParams(int model_id) {
  return InitialParams(model_id, 500, 2048, 1024);
}

TEST(Registry, NamesAndIds) {
  EXPECT_EQ(ModelIdFromName("PINHOLE"), 1);
  EXPECT_EQ(ModelIdFromName("OPENCV"), 4);
  EXPECT_EQ(ModelIdFromName("EUCM"), 16);
  EXPECT_EQ(ModelIdFromName("EQUIRECTANGULAR"), 17);
  EXPECT_EQ(ModelIdFromName("UNIFIED_OMNI"), 64);
  EXPECT_EQ(ModelIdFromName("DOUBLE_SPHERE"), 65);
  EXPECT_EQ(ModelIdFromName("OPENCV_FISHEYE"), 5);
  EXPECT_EQ(ModelIdFromName("THIN_PRISM_FISHEYE"), 10);
  EXPECT_EQ(ModelIdFromName("OCAM"), 66);
  EXPECT_EQ(ModelIdFromName("FOO"), -1);
  EXPECT_EQ(ModelIdFromName("eucm"), -1);
  EXPECT_EQ(static_cast<int>(ModelId::kEquirectangular), 17);
  EXPECT_EQ(static_cast<int>(ModelId::kDoubleSphere), 65);

  std::vector<int> sphere_ids;
  for (const ModelInfo& info : SphereModels()) {
    sphere_ids.push_back(info.id);
    EXPECT_EQ(ModelIdFromName(info.name), info.id);
    EXPECT_EQ(static_cast<int>(InitialParams(info.id, 1, 2, 1).size()),
              info.num_params);
  }
  EXPECT_EQ(sphere_ids, (std::vector<int>{5, 10, 16, 17, 64, 65, 66}));
  for (int id : {5, 10, 16, 17, 64, 65, 66}) EXPECT_TRUE(IsSphereModel(id));
  // PINHOLE and OPENCV are known but left to COLMAP's own handling.
  for (int id : {0, 1, 4, -1}) EXPECT_FALSE(IsSphereModel(id));
}

TEST(Registry, FisheyeAndOCamDispatch) {
  for (int id : {5, 10, 66}) {
    const std::vector<double> params = InitialParams(id, 300, 640, 480);
    EXPECT_EQ(CheckParams(id, params, 640, 480), "") << id;
    const Eigen::Vector3d ray(0.2, -0.1, 0.9);
    Eigen::Vector2d pixel;
    Eigen::Vector3d back;
    ASSERT_TRUE(ImageFromRay(id, params, ray, &pixel)) << id;
    ASSERT_TRUE(RayFromImage(id, params, pixel, &back)) << id;
    EXPECT_LT((back - ray.normalized()).norm(), 1e-12) << id;
    EXPECT_NEAR(PixelToAngle(id, params), 1.0 / 300, 1e-15) << id;
    EXPECT_THROW(ImageFromRay(id, {300, 300, 320, 240}, ray, &pixel),
                 std::invalid_argument);
  }
  EXPECT_EQ(InitialParams(5, 300, 640, 480),
            (std::vector<double>{300, 300, 320, 240, 0, 0, 0, 0}));
  EXPECT_EQ(InitialParams(66, 300, 640, 480),
            (std::vector<double>{320, 240, 1, 0, 0, -300, 0, 0, 0}));
}

TEST(Registry, InitialParamsAreValid) {
  for (int id : kAllIds) {
    EXPECT_EQ(CheckParams(id, ValidParams(id), 2048, 1024), "") << id;
    EXPECT_EQ(CheckParams(id, ValidParams(id), 0, 0), "") << id;
  }
  EXPECT_EQ(InitialParams(16, 300, 640, 480),
            (std::vector<double>{300, 300, 320, 240, 0.5, 1.0}));
  EXPECT_EQ(InitialParams(64, 300, 640, 480),
            (std::vector<double>{300, 300, 320, 240, 1, 0, 0, 0, 0}));
  EXPECT_EQ(InitialParams(65, 300, 640, 480),
            (std::vector<double>{300, 300, 320, 240, 0, 0.5}));
}

TEST(Registry, UnknownIdThrows) {
  const std::vector<double> params = {1, 2, 3, 4};
  Eigen::Vector2d pixel;
  Eigen::Vector3d ray(0, 0, 1);
  for (int id : {0, 2, 67, -3}) {
    try {
      CheckParams(id, params, 0, 0);
      FAIL() << "no throw for " << id;
    } catch (const std::invalid_argument& e) {
      EXPECT_THAT(e.what(), HasSubstr(std::to_string(id)));
    }
    EXPECT_THROW(ImageFromRay(id, params, ray, &pixel), std::invalid_argument);
    EXPECT_THROW(RayFromImage(id, params, pixel, &ray), std::invalid_argument);
    EXPECT_THROW(PixelToAngle(id, params), std::invalid_argument);
    EXPECT_THROW(InitialParams(id, 1, 2, 1), std::invalid_argument);
  }
}

TEST(Registry, DispatchMatchesModel) {
  const std::vector<double> params = {300, 301, 320, 240, 0.9, 0.01, 0, 0, 0};
  const Eigen::Vector3d ray(0.3, -0.4, 0.5);
  Eigen::Vector2d pixel, expected;
  ASSERT_TRUE(ImageFromRay(64, params, ray, &pixel));
  ASSERT_TRUE(
      UnifiedOmniModel::ImageFromRay(params.data(), ray.data(), expected.data()));
  EXPECT_EQ(pixel, expected);
  Eigen::Vector3d ray_back;
  ASSERT_TRUE(RayFromImage(64, params, pixel, &ray_back));
  EXPECT_LT((ray_back - ray.normalized()).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(PixelToAngle(64, params), 1.9 / 300.5);
  // A short vector must not be read past its end.
  EXPECT_THROW(ImageFromRay(64, {300, 300, 320, 240}, ray, &pixel),
               std::invalid_argument);
}

TEST(CheckParams, WrongCountNamesModelAndCounts) {
  for (int id : kAllIds) {
    std::vector<double> params = ValidParams(id);
    const std::string expected_count = std::to_string(params.size());
    params.push_back(1);
    const std::string message = CheckParams(id, params, 0, 0);
    EXPECT_THAT(message, HasSubstr(expected_count));
    EXPECT_THAT(message, HasSubstr(std::to_string(params.size())));
    const std::string name = internal::VisitModel(
        id, [](auto model) { return decltype(model)::kModelName; });
    EXPECT_THAT(message, HasSubstr(name));
    EXPECT_NE(CheckParams(id, {}, 0, 0), "");
  }
}

TEST(CheckParams, NonFiniteNamesParameter) {
  for (int id : {1, 4, 16, 64, 65}) {
    const std::vector<double> valid = ValidParams(id);
    for (size_t i = 0; i < valid.size(); ++i) {
      for (double bad : {std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::infinity(),
                         -std::numeric_limits<double>::infinity()}) {
        std::vector<double> params = valid;
        params[i] = bad;
        const std::string message = CheckParams(id, params, 0, 0);
        const std::string name = internal::ParamName(
            id == 1   ? PinholeModel::kParamsInfo
            : id == 4 ? OpenCVModel::kParamsInfo
            : id == 16 ? EUCMModel::kParamsInfo
            : id == 64 ? UnifiedOmniModel::kParamsInfo
                       : DoubleSphereModel::kParamsInfo,
            static_cast<int>(i));
        EXPECT_THAT(message, HasSubstr(name + "=")) << id << " " << i;
      }
    }
  }
  EXPECT_THAT(CheckParams(17, {NAN, 1024}, 0, 0), HasSubstr("w=nan"));
  EXPECT_THAT(CheckParams(17, {2048, INFINITY}, 0, 0), HasSubstr("h=inf"));
}

TEST(CheckParams, NonPositiveFocalNamesParameter) {
  for (int id : {1, 4, 16, 64, 65}) {
    std::vector<double> params = ValidParams(id);
    params[0] = -500;
    EXPECT_THAT(CheckParams(id, params, 0, 0), HasSubstr("fx=-500")) << id;
    params = ValidParams(id);
    params[1] = 0;
    EXPECT_THAT(CheckParams(id, params, 0, 0), HasSubstr("fy=0")) << id;
  }
  EXPECT_THAT(CheckParams(17, {-2048, -1024}, 0, 0), HasSubstr("w=-2048"));
}

TEST(CheckParams, EquirectangularSize) {
  EXPECT_EQ(CheckParams(17, {5000, 2688}, 0, 0),
            "EQUIRECTANGULAR: width w=5000 must be twice height h=2688");
  EXPECT_EQ(CheckParams(17, {100, 50}, 5376, 2688),
            "EQUIRECTANGULAR params w,h = 100,50 differ from the image size "
            "5376x2688");
  EXPECT_EQ(CheckParams(17, {100, 50}, 0, 0), "");
  EXPECT_EQ(CheckParams(17, {5376, 2688}, 5376, 2688), "");
}

TEST(CheckParams, ModelSpecificRanges) {
  const std::vector<double> eucm = {300, 300, 320, 240, 0.6, 1.1};
  EXPECT_EQ(CheckParams(16, eucm, 0, 0), "");
  for (double alpha : {-0.1, 1.01}) {
    auto params = eucm;
    params[4] = alpha;
    EXPECT_THAT(CheckParams(16, params, 0, 0), HasSubstr("alpha="));
  }
  for (double beta : {0.0, -1.0}) {
    auto params = eucm;
    params[5] = beta;
    EXPECT_THAT(CheckParams(16, params, 0, 0), HasSubstr("beta="));
  }

  const std::vector<double> ds = {300, 300, 320, 240, -0.2, 0.6};
  EXPECT_EQ(CheckParams(65, ds, 0, 0), "");
  for (double alpha : {-0.01, 1.5}) {
    auto params = ds;
    params[5] = alpha;
    EXPECT_THAT(CheckParams(65, params, 0, 0), HasSubstr("alpha="));
  }
  for (double xi : {-1.0, -2.0, 1.01}) {
    auto params = ds;
    params[4] = xi;
    EXPECT_THAT(CheckParams(65, params, 0, 0), HasSubstr("xi="));
  }
  auto ds_edge = ds;
  ds_edge[4] = 1.0;
  EXPECT_EQ(CheckParams(65, ds_edge, 0, 0), "");

  std::vector<double> omni = {300, 300, 320, 240, 1.1, 0.01, 0, 0, 0};
  EXPECT_EQ(CheckParams(64, omni, 0, 0), "");
  omni[4] = -0.1;
  EXPECT_THAT(CheckParams(64, omni, 0, 0), HasSubstr("xi=-0.1"));
}

}  // namespace
}  // namespace sphera
