// The global mapper's bundle adjustments with SPHERA's held lenses. Its
// first adjustments start from poses found by rotation averaging and global
// positioning, with every track at once: on a short real rig capture they
// bend the lenses' intrinsics far from their start (a GoPro Fusion's
// lenses from 1629 px to 2147 and 2332 px, then out of DOUBLE_SPHERE's
// range) and every track is filtered. The lenses of multi-camera rigs are
// held through those adjustments and refined from the retriangulation on,
// and a camera whose self-calibration runs away is set back and held, as in
// the incremental mapper (DivergedCameraHold).
#pragma once

#include "colmap/estimators/bundle_adjustment.h"
#include "colmap/scene/database_cache.h"
#include "colmap/scene/reconstruction.h"
#include "colmap_ext/scene/intrinsics_divergence.h"

#include <unordered_set>

namespace colmap {

// Bundle adjustment of every posed image of `reconstruction` (gauge: two
// cameras), the intrinsics of `constant_intrinsics` held. True when the
// solution is usable.
bool AdjustPosedImages(const BundleAdjustmentOptions& options,
                       const std::unordered_set<camera_t>& constant_intrinsics,
                       Reconstruction& reconstruction);

// AdjustPosedImages as the global mapper's: the cameras `hold` holds, and with
// `hold_rig_lenses` each camera of a rig of several sensors, keep their
// intrinsics; afterwards a camera that diverged from its prior in
// `database_cache` is set back and held. True when the solution is usable.
bool RunHeldBundleAdjustment(const BundleAdjustmentOptions& options,
                             const DatabaseCache& database_cache,
                             const IntrinsicsDivergenceOptions& hold_options,
                             bool hold_rig_lenses,
                             DivergedCameraHold& hold,
                             Reconstruction& reconstruction);

}  // namespace colmap
