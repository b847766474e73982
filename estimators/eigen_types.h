// SPHERA estimators: fixed-size Eigen typedefs shared with COLMAP.
//
// COLMAP declares the same alias (Eigen::Matrix3x4d) in colmap/util/types.h.
// Re-declaring an alias of the same type is legal C++, so both headers can be
// included in one translation unit without conflict.
#pragma once

#include <Eigen/Core>

namespace Eigen {
typedef Eigen::Matrix<double, 3, 4> Matrix3x4d;
}  // namespace Eigen
