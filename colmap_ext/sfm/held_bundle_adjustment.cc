#include "colmap_ext/sfm/held_bundle_adjustment.h"

namespace colmap {

bool RunHeldBundleAdjustment(const BundleAdjustmentOptions& options,
                             const DatabaseCache& database_cache,
                             const IntrinsicsDivergenceOptions& hold_options,
                             const bool hold_rig_lenses,
                             DivergedCameraHold& hold,
                             Reconstruction& reconstruction) {
  BundleAdjustmentConfig ba_config;
  for (const auto& [image_id, image] : reconstruction.Images()) {
    if (image.HasPose()) {
      ba_config.AddImage(image_id);
    }
  }
  ba_config.FixGauge(BundleAdjustmentGauge::TWO_CAMS_FROM_WORLD);

  // A rig's lens is "shown by fewer than min_rig_frames frames" for any
  // positive bound when no frame is counted: every lens of a rig is held.
  IntrinsicsDivergenceOptions constant_options = hold_options;
  constant_options.min_rig_frames = hold_rig_lenses ? 1 : 0;
  for (const camera_t camera_id : hold.ConstantIntrinsics(
           reconstruction, /*num_reg_images_per_camera=*/{}, constant_options)) {
    if (reconstruction.ExistsCamera(camera_id)) {
      ba_config.SetConstantCamIntrinsics(camera_id);
    }
  }

  hold.Remember(reconstruction);
  const bool usable =
      CreateDefaultBundleAdjuster(options, ba_config, reconstruction)
          ->Solve()
          ->IsSolutionUsable();
  hold.HoldDiverged(database_cache, hold_options, &reconstruction);
  return usable;
}

}  // namespace colmap
