// Which reprojection residual bundle adjustment and pose refinement use for
// spherical cameras (EQUIRECTANGULAR and SPHERA's EUCM, UNIFIED_OMNI,
// DOUBLE_SPHERE; perspective cameras always use COLMAP's pixel residual):
//   ANGULAR  the exact angle between the observed ray and the point's
//            direction (SPHERA paper, Eq. 4), in pixel equivalents;
//   PIXEL    upstream COLMAP's pixel residual (for EQUIRECTANGULAR with the
//            x residual wrapped at the seam).
#pragma once

#include "colmap/util/enum_utils.h"

namespace colmap {

MAKE_ENUM_CLASS_OVERLOAD_STREAM(SphereResidualType, 0, ANGULAR, PIXEL);

}  // namespace colmap
