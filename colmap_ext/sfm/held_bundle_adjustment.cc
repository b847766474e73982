#include "colmap_ext/sfm/held_bundle_adjustment.h"

namespace colmap {

bool AdjustPosedImages(const BundleAdjustmentOptions& options,
                       const std::unordered_set<camera_t>& constant_intrinsics,
                       Reconstruction& reconstruction) {
  BundleAdjustmentConfig ba_config;
  for (const auto& [image_id, image] : reconstruction.Images()) {
    if (image.HasPose()) {
      ba_config.AddImage(image_id);
    }
  }
  for (const camera_t camera_id : constant_intrinsics) {
    if (reconstruction.ExistsCamera(camera_id)) {
      ba_config.SetConstantCamIntrinsics(camera_id);
    }
  }
  ba_config.FixGauge(BundleAdjustmentGauge::TWO_CAMS_FROM_WORLD);
  return CreateDefaultBundleAdjuster(options, ba_config, reconstruction)
      ->Solve()
      ->IsSolutionUsable();
}

bool RunHeldBundleAdjustment(const BundleAdjustmentOptions& options,
                             const DatabaseCache& database_cache,
                             const IntrinsicsDivergenceOptions& hold_options,
                             const bool hold_rig_lenses,
                             DivergedCameraHold& hold,
                             Reconstruction& reconstruction) {
  // A rig's lens is "shown by fewer than min_rig_frames frames" for any
  // positive bound when no frame is counted: every lens of a rig is held.
  IntrinsicsDivergenceOptions constant_options = hold_options;
  constant_options.min_rig_frames = hold_rig_lenses ? 1 : 0;
  const std::unordered_set<camera_t> constant_intrinsics =
      hold.ConstantIntrinsics(
          reconstruction, /*num_reg_images_per_camera=*/{}, constant_options);
  hold.Remember(reconstruction);
  const bool usable =
      AdjustPosedImages(options, constant_intrinsics, reconstruction);
  hold.HoldDiverged(database_cache, hold_options, &reconstruction);
  return usable;
}

}  // namespace colmap
