#include "estimators/angular_residual.h"

#include <cmath>
#include <random>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include "camera_models/unified_omni.h"
#include "estimators/tests/test_utils.h"

namespace sphera {
namespace {

// AngularLogResidual on Eigen vectors.
Eigen::Vector2d LogResidual(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  Eigen::Vector2d r;
  AngularLogResidual(u.data(), v.data(), r.data());
  return r;
}

std::vector<Eigen::Vector3d> TestRays(std::mt19937* rng) {
  std::vector<Eigen::Vector3d> rays = {
      Eigen::Vector3d::UnitX(),  -Eigen::Vector3d::UnitX(),
      Eigen::Vector3d::UnitY(),  -Eigen::Vector3d::UnitY(),
      Eigen::Vector3d::UnitZ(),  -Eigen::Vector3d::UnitZ(),
      Eigen::Vector3d(1, 1, 0).normalized(),  // on the basis switch u_z = 0
      Eigen::Vector3d(1, 2, -1e-12).normalized(),
      Eigen::Vector3d(1, 2, 1e-12).normalized()};
  for (int i = 0; i < 40; ++i) rays.push_back(test::RandomUnitVector(rng));
  return rays;
}

TEST(AngularResidual, TangentBasisIsOrthonormalRightHanded) {
  std::mt19937 rng(1);
  for (const Eigen::Vector3d& u : TestRays(&rng)) {
    Eigen::Vector3d e1, e2;
    RayTangentBasis(u, &e1, &e2);
    EXPECT_NEAR(e1.norm(), 1, 1e-14);
    EXPECT_NEAR(e2.norm(), 1, 1e-14);
    EXPECT_NEAR(e1.dot(e2), 0, 1e-14);
    EXPECT_NEAR(e1.dot(u), 0, 1e-14);
    EXPECT_NEAR(e2.dot(u), 0, 1e-14);
    EXPECT_LT((e1.cross(e2) - u).norm(), 1e-14);
  }
}

TEST(AngularResidual, SquaredNormEqualsSquaredGeodesicAngle) {
  std::mt19937 rng(2);
  std::vector<double> angles;
  // 1e-8 rad .. 179 deg, log-spaced, plus both sides of the series threshold.
  const double max_angle = 179.0 * M_PI / 180.0;
  for (int i = 0; i <= 200; ++i) {
    angles.push_back(1e-8 * std::pow(max_angle / 1e-8, i / 200.0));
  }
  for (double a : {0.00999, 0.01, 0.01001, 0.0099999, 0.0100001}) {
    angles.push_back(a);
  }
  std::uniform_real_distribution<double> log_scale(-3, 3);
  int num_checked = 0;
  for (const Eigen::Vector3d& u : TestRays(&rng)) {
    for (double theta : angles) {
      const Eigen::Vector3d w = test::RandomTangent(u, &rng);
      const double scale = std::pow(10.0, log_scale(rng));
      const Eigen::Vector3d v =
          scale * (std::cos(theta) * u + std::sin(theta) * w);
      const Eigen::Vector2d r = LogResidual(u, v);
      ASSERT_TRUE(r.allFinite());
      EXPECT_NEAR(r.squaredNorm(), theta * theta, 1e-12)
          << "theta=" << theta << " u=" << u.transpose();
      EXPECT_NEAR(r.norm(), theta, 1e-12) << "theta=" << theta;
      // Direction of the log map = tangent direction of the error.
      Eigen::Vector3d e1, e2;
      RayTangentBasis(u, &e1, &e2);
      const Eigen::Vector3d dir = r(0) * e1 + r(1) * e2;
      EXPECT_LT((dir / r.norm() - w).norm(), 1e-6) << "theta=" << theta;
      // Double helper agrees.
      EXPECT_NEAR(AngleBetweenRays(u, v), theta, 1e-12);
      ++num_checked;
    }
  }
  EXPECT_GT(num_checked, 9000);
}

TEST(AngularResidual, AntipodeAndZeroAreFinite) {
  const Eigen::Vector3d u(0, 0, 1);
  const Eigen::Vector2d r_anti = LogResidual(u, -u);
  EXPECT_NEAR(r_anti.norm(), M_PI, 1e-15);
  const Eigen::Vector2d r_zero_err = LogResidual(u, 3.0 * u);
  EXPECT_EQ(r_zero_err.norm(), 0.0);
}

// Central differences of AngularReprojectionConstantPoseCost w.r.t. the
// point: the log-map residual through LogMapResidualFromComponents, whose
// Jets the camera-only BA and triangulation refinement differentiate.
void CheckJacobianAgainstCentralDifferences(const Eigen::Vector3d& observed,
                                            const Eigen::Matrix3d& R,
                                            const Eigen::Vector3d& t,
                                            const Eigen::Vector3d& X,
                                            double tol) {
  std::unique_ptr<ceres::CostFunction> cost(
      AngularReprojectionConstantPoseCost::Create(observed, R, t));
  const double* p[1] = {X.data()};
  double r[2];
  Eigen::Matrix<double, 2, 3, Eigen::RowMajor> J;
  double* Jp[1] = {J.data()};
  ASSERT_TRUE(cost->Evaluate(p, r, Jp));
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d plus = X, minus = X;
    plus(k) += h;
    minus(k) -= h;
    const double* pp[1] = {plus.data()};
    const double* pm[1] = {minus.data()};
    double rp[2], rm[2];
    ASSERT_TRUE(cost->Evaluate(pp, rp, nullptr));
    ASSERT_TRUE(cost->Evaluate(pm, rm, nullptr));
    for (int i = 0; i < 2; ++i) {
      const double numeric = (rp[i] - rm[i]) / (2 * h);
      ASSERT_TRUE(std::isfinite(J(i, k)));
      EXPECT_NEAR(J(i, k), numeric, tol * std::max(1.0, std::abs(numeric)))
          << "param " << k << " residual " << i;
    }
  }
}

TEST(AngularResidual, CeresJacobianMatchesCentralDifferences) {
  std::mt19937 rng(3);
  for (double err_angle : {1e-3, 2e-2, 0.3, 1.5, 2.5}) {
    for (int trial = 0; trial < 10; ++trial) {
      const Eigen::Matrix3d R = test::RandomRotation(&rng);
      const Eigen::Vector3d t = test::RandomUnitVector(&rng);
      const Eigen::Vector3d X = 3.0 * test::RandomUnitVector(&rng);
      const Eigen::Vector3d v = (R * X + t).normalized();
      const Eigen::Vector3d observed = test::PerturbRay(v, err_angle, &rng);
      CheckJacobianAgainstCentralDifferences(observed, R, t, X, 1e-6);
    }
  }
}

TEST(AngularResidual, JacobianFiniteAndCorrectAtZeroError) {
  std::mt19937 rng(4);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3d R = test::RandomRotation(&rng);
    const Eigen::Vector3d t = test::RandomUnitVector(&rng);
    const Eigen::Vector3d X = 4.0 * test::RandomUnitVector(&rng);
    const Eigen::Vector3d v = R * X + t;
    const Eigen::Vector3d u = v.normalized();
    std::unique_ptr<ceres::CostFunction> cost(
        AngularReprojectionConstantPoseCost::Create(u, R, t));
    const double* p[1] = {X.data()};
    double r[2];
    Eigen::Matrix<double, 2, 3, Eigen::RowMajor> J;
    double* Jp[1] = {J.data()};
    ASSERT_TRUE(cost->Evaluate(p, r, Jp));
    EXPECT_NEAR(r[0], 0, 1e-15);
    EXPECT_NEAR(r[1], 0, 1e-15);
    ASSERT_TRUE(J.allFinite());
    // At zero error dr/dv = [e1; e2] / |v|, so dr/dX = [e1; e2] R / |v|.
    Eigen::Vector3d e1, e2;
    RayTangentBasis(u, &e1, &e2);
    Eigen::Matrix<double, 2, 3> expected;
    expected.row(0) = e1.transpose() * R / v.norm();
    expected.row(1) = e2.transpose() * R / v.norm();
    EXPECT_LT((J - expected).norm(), 1e-12);
  }
}

// The double version with its analytic Jacobian gives the templated
// residual and the Jet derivative within rounding, on both
// sides of the small-angle series, near the antipode and at zero error.
TEST(AngularResidual, AnalyticJacobianMatchesJets) {
  std::mt19937 rng(5);
  using Jet3 = ceres::Jet<double, 3>;
  std::vector<double> angles = {0.0, 1e-9, 1e-5, 0.0099, 0.0101, 0.3, 1.5,
                                2.5, 3.1};
  int num_checked = 0;
  for (const Eigen::Vector3d& u : TestRays(&rng)) {
    for (double theta : angles) {
      const Eigen::Vector3d w = test::RandomTangent(u, &rng);
      const Eigen::Vector3d v =
          0.7 * (std::cos(theta) * u + std::sin(theta) * w);
      double r[2];
      Eigen::Matrix<double, 2, 3, Eigen::RowMajor> J;
      AngularLogResidualWithJacobian(u.data(), v.data(), r, J.data());
      const Jet3 u_jet[3] = {Jet3(u(0)), Jet3(u(1)), Jet3(u(2))};
      const Jet3 v_jet[3] = {Jet3(v(0), 0), Jet3(v(1), 1), Jet3(v(2), 2)};
      Jet3 r_jet[2];
      AngularLogResidual(u_jet, v_jet, r_jet);
      for (int row = 0; row < 2; ++row) {
        EXPECT_NEAR(r[row], r_jet[row].a, 1e-15 * (1 + std::abs(r[row])));
        for (int col = 0; col < 3; ++col) {
          EXPECT_NEAR(J(row, col), r_jet[row].v[col],
                      1e-9 * (1 + std::abs(r_jet[row].v[col])))
              << "theta " << theta << " row " << row << " col " << col;
        }
      }
      double r_only[2];
      AngularLogResidualWithJacobian(u.data(), v.data(), r_only, nullptr);
      EXPECT_EQ(r_only[0], r[0]);
      EXPECT_EQ(r_only[1], r[1]);
      ++num_checked;
    }
  }
  EXPECT_EQ(num_checked, 49 * 9);
  // Antipode: (pi, 0) and a zero Jacobian, as the templated version.
  const Eigen::Vector3d u = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d v = -2 * u;
  double r[2];
  double J[6] = {1, 1, 1, 1, 1, 1};
  AngularLogResidualWithJacobian(u.data(), v.data(), r, J);
  EXPECT_EQ(r[0], M_PI);
  EXPECT_EQ(r[1], 0);
  for (double x : J) EXPECT_EQ(x, 0);
}

// A model whose lift succeeds in doubles and fails in Jets: what rounding
// does to a pixel at the edge of a real model's domain.
struct LiftsOnlyInDoubles {
  static constexpr int kNumParams = 1;
  template <typename T>
  static bool RayFromImage(const T* params, const T* pixel, T* ray) {
    if constexpr (!std::is_same_v<T, double>) {
      return false;
    } else {
      if (pixel[0] > params[0]) return false;
      ray[0] = pixel[0] / params[0];
      ray[1] = 0;
      ray[2] = std::sqrt(1 - ray[0] * ray[0]);
      return true;
    }
  }
};

TEST(RayFromImageOrScalarRay, TakesTheScalarRayWhereOnlyTheJetLiftFails) {
  using Jet = ceres::Jet<double, 1>;
  const Jet params[1] = {Jet(2.0, 0)};
  const Jet inside[2] = {Jet(1.0), Jet(0.0)};
  Jet ray[3];
  ASSERT_FALSE(LiftsOnlyInDoubles::RayFromImage(params, inside, ray));
  ASSERT_TRUE(RayFromImageOrScalarRay<LiftsOnlyInDoubles>(params, inside, ray));
  EXPECT_DOUBLE_EQ(ray[0].a, 0.5);
  EXPECT_DOUBLE_EQ(ray[2].a, std::sqrt(0.75));
  EXPECT_EQ(ray[0].v[0], 0.0);  // no derivative by the parameter
  // Where the scalar lift fails too, so does this one.
  const Jet outside[2] = {Jet(3.0), Jet(0.0)};
  EXPECT_FALSE(
      RayFromImageOrScalarRay<LiftsOnlyInDoubles>(params, outside, ray));
  // In doubles it is the model's lift.
  const double scalar_params[1] = {2.0};
  const double scalar_pixel[2] = {1.0, 0.0};
  double scalar_ray[3];
  ASSERT_TRUE(RayFromImageOrScalarRay<LiftsOnlyInDoubles>(
      scalar_params, scalar_pixel, scalar_ray));
  EXPECT_DOUBLE_EQ(scalar_ray[0], 0.5);
}

// A UNIFIED_OMNI lens whose radial distortion folds inside its frame (the
// parameters bundle adjustment reached on a rendered 8-lens ring): over
// pixels across the fold, the lift with derivatives succeeds exactly where
// the lift in doubles does, and then with the same ray. (Without the
// fallback, ceres::Jet's rounding fails a few of these pixels.)
TEST(RayFromImageOrScalarRay, AgreesWithTheScalarLiftAcrossAFold) {
  const double params[9] = {457.71797860362676,    457.1763972184234,
                            512,                   512,
                            0.96675571178944697,   -0.031945239643560254,
                            -0.04826473796719391,  -0.00012990444376227066,
                            0.0011993448409999166};
  using Jet = ceres::Jet<double, 9>;
  Jet jet_params[9];
  for (int i = 0; i < 9; ++i) jet_params[i] = Jet(params[i], i);
  int lifted = 0;
  int not_lifted = 0;
  for (double dx = -0.0005; dx <= 0.0005; dx += 0.000002) {
    for (double dy = -0.0005; dy <= 0.0005; dy += 0.00002) {
      const double pixel[2] = {678.064 + dx, 965.723 + dy};
      double ray[3];
      const bool scalar = UnifiedOmniModel::RayFromImage(params, pixel, ray);
      const Jet jet_pixel[2] = {Jet(pixel[0]), Jet(pixel[1])};
      Jet jet_ray[3];
      const bool with_derivatives = RayFromImageOrScalarRay<UnifiedOmniModel>(
          jet_params, jet_pixel, jet_ray);
      if (scalar) {
        ASSERT_TRUE(with_derivatives) << pixel[0] << " " << pixel[1];
        for (int i = 0; i < 3; ++i) {
          EXPECT_NEAR(jet_ray[i].a, ray[i], 1e-9);
        }
        ++lifted;
      } else {
        ++not_lifted;
      }
    }
  }
  // The grid spans the fold.
  EXPECT_GT(lifted, 1000);
  EXPECT_GT(not_lifted, 1000);
}

}  // namespace
}  // namespace sphera
