// The manifold of a lens's pose in its rig (sensor_from_rig: a unit
// quaternion, then the translation) in bundle adjustment. Upstream refines
// the pose whole or holds it whole. A capture that mostly turns in place
// measures the lenses' rotations well (every pair of views shares rays) but
// hardly their few centimetres of offset, and refined freely the offset runs
// to metres and bends the rotation with it (a GoPro Fusion's back lens from
// 179 to 151 degrees). Holding the lens's centre in the rig keeps the rig
// config's offset (a preset's nominal one) while the rotation is refined.
#pragma once

#include "colmap/estimators/cost_functions/manifold.h"

#include <memory>

#include <Eigen/Geometry>
#include <ceres/manifold.h>

namespace colmap {

// sensor_from_rig = (q, t) turned about the lens's centre in the rig,
// c = -R(q)^T t, which stays: with Ceres's quaternion step
// q' = Exp(delta) q, the translation follows as t' = Exp(delta) t (then
// -R(q')^T t' = c). Tangent: the 3 rotation coordinates of Ceres's
// EigenQuaternionManifold.
class RotationAboutCentreManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 3; }

  bool Plus(const double* x,
            const double* delta,
            double* x_plus_delta) const override {
    if (!quaternion_.Plus(x, delta, x_plus_delta)) {
      return false;
    }
    // Exp(delta) = q' q^-1.
    const Eigen::Quaterniond q(x);
    const Eigen::Quaterniond q_plus(x_plus_delta);
    Eigen::Map<Eigen::Vector3d>(x_plus_delta + 4) =
        (q_plus * q.inverse()) * Eigen::Map<const Eigen::Vector3d>(x + 4);
    return true;
  }

  bool PlusJacobian(const double* x, double* jacobian) const override {
    // Rows 0-3: the quaternion's; rows 4-6: d(Exp(delta) t)/d delta at 0
    // = -2 [t]x (Ceres's step turns by twice |delta|).
    Eigen::Map<Eigen::Matrix<double, 7, 3, Eigen::RowMajor>> J(jacobian);
    double quaternion_jacobian[12];
    if (!quaternion_.PlusJacobian(x, quaternion_jacobian)) {
      return false;
    }
    J.topRows<4>() =
        Eigen::Map<const Eigen::Matrix<double, 4, 3, Eigen::RowMajor>>(
            quaternion_jacobian);
    const Eigen::Vector3d t(x[4], x[5], x[6]);
    Eigen::Matrix3d t_cross;
    t_cross << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
    J.bottomRows<3>() = -2 * t_cross;
    return true;
  }

  bool Minus(const double* y,
             const double* x,
             double* y_minus_x) const override {
    return quaternion_.Minus(y, x, y_minus_x);
  }

  bool MinusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 3, 7, Eigen::RowMajor>> J(jacobian);
    double quaternion_jacobian[12];
    if (!quaternion_.MinusJacobian(x, quaternion_jacobian)) {
      return false;
    }
    J.leftCols<4>() =
        Eigen::Map<const Eigen::Matrix<double, 3, 4, Eigen::RowMajor>>(
            quaternion_jacobian);
    J.rightCols<3>().setZero();
    return true;
  }

 private:
  ceres::EigenQuaternionManifold quaternion_;
};

// The manifold of a sensor_from_rig parameter block: the rotation on the
// unit quaternions, and the lens's offset free or, without
// `refine_translation`, its centre in the rig held.
inline std::unique_ptr<ceres::Manifold> CreateSensorFromRigManifold(
    bool refine_translation) {
  if (refine_translation) {
    return CreateProductManifold(CreateEigenQuaternionManifold(),
                                 CreateEuclideanManifold<3>());
  }
  return std::make_unique<RotationAboutCentreManifold>();
}

}  // namespace colmap
