// When a lens's self-calibration has run away (e.g. a real 197° lens whose
// bundle adjustment ended at fx = 97,205 and fy = 29 pixels): the mapper
// holds such a camera at its value before the adjustment instead of
// returning it (patch "Mapper: a lens whose self-calibration runs away is
// held and reported").
#pragma once

#include "colmap/scene/camera.h"

#include <string>
#include <vector>

namespace colmap {

struct IntrinsicsDivergenceOptions {
  // The refined mean focal length may differ from the prior's (the
  // database's: EXIF, the user's or the rig config's) by this factor.
  double max_focal_ratio = 4.0;
  // A camera with fx = fy in its prior may end with fx / fy this far from 1.
  double max_aspect_change = 0.2;
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

// The cameras the mappers of this process held since the last
// TakeHeldCameras(), in the order they were held, for the mapper's closing
// report: the camera as held (id, model, params) and why. Thread-safe.
struct HeldCamera {
  Camera camera;
  std::string reason;
};
void RecordHeldCamera(const Camera& camera, const std::string& reason);
std::vector<HeldCamera> TakeHeldCameras();

}  // namespace colmap
