#include "colmap_ext/scene/intrinsics_divergence.h"

#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>

namespace colmap {

std::string IntrinsicsDivergence(const Camera& prior,
                                 const Camera& refined,
                                 const IntrinsicsDivergenceOptions& options) {
  std::ostringstream why;
  for (const double value : refined.params) {
    if (!std::isfinite(value)) {
      why << "a parameter is not finite (" << refined.ParamsToString() << ")";
      return why.str();
    }
  }
  // Only the model's own validity (SPHERA's sphere models check their
  // parameter ranges; COLMAP's models their focal length and principal
  // point), not COLMAP's focal-ratio heuristics.
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (refined.HasBogusParams(0, kInf, kInf)) {
    why << "the parameters left the valid range of " << refined.ModelName()
        << " (" << refined.ParamsToString() << ")";
    return why.str();
  }
  if (prior.model_id != refined.model_id ||
      refined.FocalLengthIdxs().empty()) {
    return "";
  }
  const double ratio = refined.MeanFocalLength() / prior.MeanFocalLength();
  if (!(ratio <= options.max_focal_ratio &&
        ratio >= 1 / options.max_focal_ratio)) {
    why << "the focal length went from " << prior.MeanFocalLength() << " to "
        << refined.MeanFocalLength() << " pixels";
    if (refined.FocalLengthIdxs().size() > 1) {
      why << " (fx " << refined.FocalLengthX() << ", fy "
          << refined.FocalLengthY() << ")";
    }
    return why.str();
  }
  if (refined.FocalLengthIdxs().size() > 1 &&
      prior.FocalLengthX() == prior.FocalLengthY()) {
    const double aspect = refined.FocalLengthX() / refined.FocalLengthY();
    if (std::abs(aspect - 1) > options.max_aspect_change) {
      why << "a square-pixel lens ended with fx / fy = " << aspect << " (fx "
          << refined.FocalLengthX() << ", fy " << refined.FocalLengthY()
          << ")";
      return why.str();
    }
  }
  if (!refined.PrincipalPointIdxs().empty()) {
    const double x = refined.PrincipalPointX(), y = refined.PrincipalPointY();
    if (x < 0 || y < 0 || x > refined.width || y > refined.height) {
      why << "the principal point (" << x << ", " << y
          << ") left the image";
      return why.str();
    }
  }
  return "";
}

namespace {

std::mutex& HeldCamerasMutex() {
  static std::mutex mutex;
  return mutex;
}

std::vector<HeldCamera>& HeldCameraList() {
  static std::vector<HeldCamera> held;
  return held;
}

}  // namespace

void RecordHeldCamera(const Camera& camera, const std::string& reason) {
  const std::lock_guard<std::mutex> lock(HeldCamerasMutex());
  HeldCameraList().push_back({camera, reason});
}

std::vector<HeldCamera> TakeHeldCameras() {
  const std::lock_guard<std::mutex> lock(HeldCamerasMutex());
  std::vector<HeldCamera> held;
  held.swap(HeldCameraList());
  return held;
}

}  // namespace colmap
