// The manifold of a lens's pose in its rig (sensor_from_rig) in COLMAP's
// bundle adjustment: upstream's (rotation and offset refined), or with
// BundleAdjustmentOptions::refine_sensor_from_rig_translation off, the
// rotation refined about the lens's centre, which stays
// (estimators/rig_manifold.h). Upstream refines the pose whole or holds it
// whole.
#pragma once

#include "colmap/estimators/cost_functions/manifold.h"

#include "estimators/rig_manifold.h"

#include <memory>

namespace colmap {

inline std::unique_ptr<ceres::Manifold> CreateSensorFromRigManifold(
    bool refine_translation) {
  if (refine_translation) {
    return CreateProductManifold(CreateEigenQuaternionManifold(),
                                 CreateEuclideanManifold<3>());
  }
  return std::make_unique<sphera::RotationAboutCentreManifold>();
}

}  // namespace colmap
