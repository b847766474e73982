// When a lens's self-calibration has run away (e.g. a real 197° lens whose
// bundle adjustment ended at fx = 97,205 and fy = 29 pixels): the mapper
// holds such a camera at its value before the adjustment instead of
// returning it (patch "Mapper: a lens whose self-calibration runs away is
// held and reported").
#pragma once

#include "colmap/scene/camera.h"
#include "colmap/scene/database_cache.h"
#include "colmap/scene/reconstruction.h"
#include "colmap/util/hash_containers.h"

#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace colmap {

struct IntrinsicsDivergenceOptions {
  // The refined mean focal length may differ from the prior's (the
  // database's: EXIF, the user's or the rig config's) by this factor.
  double max_focal_ratio = 4.0;
  // A camera with fx = fy in its prior may end with fx / fy this far from 1.
  double max_aspect_change = 0.2;
  // A lens of a rig of several sensors keeps its intrinsics until this many
  // registered frames show it (DivergedCameraHold::ConstantIntrinsics); 0,
  // the default: refined from the start, as upstream does. Measured on the
  // real GoPro Fusion photos (docs/rigs.md), 3 helps a Kannala-Brandt start
  // and hurts the DOUBLE_SPHERE one, so it is not the default.
  int min_rig_frames = 0;
};

// Empty when `refined` is a plausible refinement of `prior` (the same
// camera); otherwise why it is not: parameters that are not finite or that
// leave the model's valid range, a focal length off by more than
// max_focal_ratio, a square-pixel camera whose fx / fy moved by more than
// max_aspect_change, a principal point outside the image.
std::string IntrinsicsDivergence(
    const Camera& prior,
    const Camera& refined,
    const IntrinsicsDivergenceOptions& options = IntrinsicsDivergenceOptions());

// A camera the mapper held, as held (id, model, params), and why.
struct HeldCamera {
  Camera camera;
  std::string reason;
};

// The cameras one incremental mapper holds: around each bundle adjustment,
// Remember() the cameras' parameters before it, and HoldDiverged() after it.
class DivergedCameraHold {
 public:
  // Remembers the parameters of every camera of `reconstruction`.
  void Remember(const Reconstruction& reconstruction);

  // Each camera of `reconstruction` that is not held yet, that
  // `database_cache` has (its prior) and whose parameters now diverge from
  // the prior's (IntrinsicsDivergence) is set back to the parameters
  // Remember() saw, held (no longer to be refined) and named in a warning.
  void HoldDiverged(const DatabaseCache& database_cache,
                    const IntrinsicsDivergenceOptions& options,
                    Reconstruction* reconstruction);

  // The cameras whose intrinsics the next bundle adjustment keeps constant:
  // the held ones, and each lens of a rig of several sensors that fewer
  // than `options.min_rig_frames` registered frames show
  // (`num_reg_images_per_camera`: the mapper's count of registered images
  // per camera; a lens has one image per frame). A rig's lens is seen once
  // per frame, so after the initial frame pair its intrinsics (a
  // Kannala-Brandt lens: 8 parameters) rest on two views of a short
  // baseline, and the first adjustments bend them; released from the
  // min_rig_frames-th frame on, they are refined with the whole model.
  // Cameras of one-sensor rigs are refined from the start, as upstream does.
  std::unordered_set<camera_t> ConstantIntrinsics(
      const Reconstruction& reconstruction,
      const FlatHashMap<camera_t, size_t>& num_reg_images_per_camera,
      const IntrinsicsDivergenceOptions& options) const;
  // In the order they were held.
  const std::vector<HeldCamera>& Held() const { return held_; }

 private:
  std::unordered_map<camera_t, std::vector<double>> params_before_;
  std::unordered_set<camera_t> held_ids_;
  std::vector<HeldCamera> held_;
};

}  // namespace colmap
