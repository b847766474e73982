// SPHERA estimators: fixed-size Eigen typedefs shared with COLMAP.
//
// COLMAP 3.10 declares exactly the same typedef in colmap/util/types.h.
// Re-declaring a typedef to the same type is legal C++, so both headers can
// be included in one translation unit without conflict.
#pragma once

#include <Eigen/Core>

namespace Eigen {
typedef Eigen::Matrix<double, 3, 4> Matrix3x4d;
}  // namespace Eigen
