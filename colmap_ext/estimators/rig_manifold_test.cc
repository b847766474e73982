// A lens pose in its rig (COLMAP's Rigid3d) refined with its centre held or
// free: a residual pulls both the rotation and the translation towards a
// target; held, the lens's centre in the rig stays where it started while the
// rotation reaches the target, free, both reach it. (The held manifold's
// Jacobians: estimators/tests/rig_manifold_test.cc.)
#include "colmap_ext/estimators/rig_manifold.h"

#include "colmap/geometry/rigid3.h"

#include <Eigen/Geometry>
#include <ceres/ceres.h>
#include <gtest/gtest.h>

namespace colmap {
namespace {

// Residual: the pose's quaternion coefficients and translation minus the
// target's (7 values).
struct PoseToTarget {
  explicit PoseToTarget(const Rigid3d& target) : target_(target) {}
  template <typename T>
  bool operator()(const T* pose, T* residual) const {
    for (int i = 0; i < 7; ++i) {
      residual[i] = pose[i] - T(target_.params[i]);
    }
    return true;
  }
  Rigid3d target_;
};

Rigid3d SolveTowards(const Rigid3d& start, const Rigid3d& target,
                     bool refine_translation, int* tangent_size) {
  Rigid3d pose = start;
  ceres::Problem problem;
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<PoseToTarget, 7, 7>(
          new PoseToTarget(target)),
      nullptr, pose.params.data());
  SetManifold(&problem, pose.params.data(),
              CreateSensorFromRigManifold(refine_translation));
  *tangent_size = ParameterBlockTangentSize(problem, pose.params.data());
  ceres::Solver::Options options;
  options.max_num_iterations = 100;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  EXPECT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  return pose;
}

class RigManifoldTest : public ::testing::Test {
 protected:
  // A back lens 180 degrees about the vertical, 4 cm behind, and a
  // target 3 degrees further and 1 cm aside.
  const Rigid3d start_{
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d(0, 0, -0.04)};
  const Rigid3d target_{
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI + 3 * M_PI / 180,
                                           Eigen::Vector3d::UnitY())),
      Eigen::Vector3d(0.01, 0, -0.04)};
};

Eigen::Vector3d CentreInRig(const Rigid3d& sensor_from_rig) {
  return -(sensor_from_rig.rotation().inverse() *
           sensor_from_rig.translation());
}

TEST_F(RigManifoldTest, HeldCentreStaysWhileTheRotationIsRefined) {
  int tangent_size = 0;
  const Rigid3d pose = SolveTowards(start_, target_, false, &tangent_size);
  EXPECT_EQ(tangent_size, 3);
  EXPECT_LT((CentreInRig(pose) - CentreInRig(start_)).norm(), 1e-12);
  // The rotation fits the target's (the translation's residual pulls
  // against it a little: the optimum is within a degree of the target).
  EXPECT_LT(pose.rotation().angularDistance(target_.rotation()),
            M_PI / 180);
  EXPECT_GT(pose.rotation().angularDistance(start_.rotation()),
            2 * M_PI / 180);
  EXPECT_NEAR(pose.rotation().norm(), 1.0, 1e-12);
}

TEST_F(RigManifoldTest, FreeTranslationIsRefinedWithTheRotation) {
  int tangent_size = 0;
  const Rigid3d pose = SolveTowards(start_, target_, true, &tangent_size);
  EXPECT_EQ(tangent_size, 6);
  EXPECT_LT((pose.translation() - target_.translation()).norm(), 1e-8);
  EXPECT_LT(pose.rotation().angularDistance(target_.rotation()), 1e-6);
}

}  // namespace
}  // namespace colmap
