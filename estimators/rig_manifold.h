// A lens's pose in its rig turned about the lens's centre, as a Ceres
// manifold. The pose is 7 numbers as COLMAP stores sensor_from_rig: a unit
// quaternion (x, y, z, w, Eigen's order), then the translation t, so the
// lens's centre in the rig is c = -R(q)^T t. The step turns q by Ceres's
// quaternion step, q' = Exp(delta) q, and the translation with it,
// t' = Exp(delta) t, so that -R(q')^T t' = c: the rotation is refined, the
// centre stays.
//
// Why: a capture that mostly turns in place measures a rig's lens rotations
// well (every pair of views shares rays) but hardly their few centimetres
// of offset; refined freely, the offset runs to metres and bends the
// rotation with it. Holding the translation alone would move the centre as
// the lens turns.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/manifold.h>

namespace sphera {

class RotationAboutCentreManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  // The 3 rotation coordinates of Ceres's EigenQuaternionManifold.
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
    if (!quaternion_.PlusJacobian(x, J.topRows<4>().data())) {
      return false;
    }
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
    // The quaternion's 3x4 block, then zeros for the translation.
    Eigen::Map<Eigen::Matrix<double, 3, 7, Eigen::RowMajor>> J(jacobian);
    Eigen::Matrix<double, 3, 4, Eigen::RowMajor> quaternion_jacobian;
    if (!quaternion_.MinusJacobian(x, quaternion_jacobian.data())) {
      return false;
    }
    J.leftCols<4>() = quaternion_jacobian;
    J.rightCols<3>().setZero();
    return true;
  }

 private:
  ceres::EigenQuaternionManifold quaternion_;
};

}  // namespace sphera
