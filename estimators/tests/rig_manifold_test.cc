// RotationAboutCentreManifold's Jacobians against finite differences of its
// Plus, Minus undoing Plus, and the product of their Jacobians the identity.
// (Held and free lens poses solved in COLMAP's layout:
// colmap_ext/estimators/rig_manifold_test.cc.)
#include "estimators/rig_manifold.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace sphera {
namespace {

TEST(RotationAboutCentreManifold, JacobiansMatchFiniteDifferences) {
  RotationAboutCentreManifold manifold;
  // (x, y, z, w) of a turn by 0.7 rad, then a translation of a few cm.
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(
      0.7, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()));
  double x[7] = {rotation.x(), rotation.y(), rotation.z(), rotation.w(),
                 0.03,         -0.01,        -0.04};
  double plus_jacobian[21];
  ASSERT_TRUE(manifold.PlusJacobian(x, plus_jacobian));
  const double h = 1e-7;
  for (int k = 0; k < 3; ++k) {
    double delta[3] = {0, 0, 0};
    double forward[7], backward[7];
    delta[k] = h;
    ASSERT_TRUE(manifold.Plus(x, delta, forward));
    delta[k] = -h;
    ASSERT_TRUE(manifold.Plus(x, delta, backward));
    for (int i = 0; i < 7; ++i) {
      EXPECT_NEAR((forward[i] - backward[i]) / (2 * h),
                  plus_jacobian[3 * i + k], 1e-6)
          << "row " << i << ", column " << k;
    }
  }
  // Minus undoes Plus, and its Jacobian times Plus's is the identity.
  const double delta[3] = {0.01, -0.02, 0.015};
  double moved[7], back[3], minus_jacobian[21];
  ASSERT_TRUE(manifold.Plus(x, delta, moved));
  ASSERT_TRUE(manifold.Minus(moved, x, back));
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(back[k], delta[k], 1e-12);
  }
  ASSERT_TRUE(manifold.MinusJacobian(x, minus_jacobian));
  const Eigen::Matrix3d product =
      Eigen::Map<Eigen::Matrix<double, 3, 7, Eigen::RowMajor>>(minus_jacobian) *
      Eigen::Map<Eigen::Matrix<double, 7, 3, Eigen::RowMajor>>(plus_jacobian);
  EXPECT_LT((product - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

}  // namespace
}  // namespace sphera
