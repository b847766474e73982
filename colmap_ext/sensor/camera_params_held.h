// Which camera parameters a refinement holds constant. COLMAP groups a
// model's parameters into focal length, principal point and extra
// parameters, and refinements free the groups they refine; a parameter in no
// group would be free in every refinement. The sphere models have such
// parameters (CameraModelFixedParamsIdxs, e.g. EQUIRECTANGULAR's w, h: the
// image size), so every refinement asks here instead of building the list
// itself: bundle adjustment, pose refinement at registration and
// sphere_bundle_adjuster.
#pragma once

#include <algorithm>
#include <vector>

#include "colmap/scene/camera.h"
#include "colmap/sensor/models.h"

namespace colmap {

// Indices held constant, sorted, without duplicates: the groups not refined,
// and always the model's fixed parameters.
inline std::vector<int> CameraParamsHeldConstant(
    const Camera& camera,
    const bool refine_focal_length,
    const bool refine_principal_point,
    const bool refine_extra_params) {
  std::vector<int> idxs;
  const auto add = [&idxs](const auto& group) {
    for (const size_t idx : group) idxs.push_back(static_cast<int>(idx));
  };
  if (!refine_focal_length) add(camera.FocalLengthIdxs());
  if (!refine_principal_point) add(camera.PrincipalPointIdxs());
  if (!refine_extra_params) add(camera.ExtraParamsIdxs());
  add(CameraModelFixedParamsIdxs(camera.model_id));
  std::sort(idxs.begin(), idxs.end());
  idxs.erase(std::unique(idxs.begin(), idxs.end()), idxs.end());
  return idxs;
}

}  // namespace colmap
