// `colmap sphere_bundle_adjuster --input_path MODEL --output_path OUT
//     [--mode camera_only|full] [--tau_px 2] [--max_iterations 20]
//     [--refine_intrinsics 0|1] [--residual angular|pixel]
//     [--loss none|cauchy] [--loss_scale_px 1]
//     [--min_observations_per_image 6]`:
// bundle adjustment of MODEL (controllers/sphere_bundle_adjustment.h), written
// to OUT (created if missing) only when it succeeded; bad options or input are
// logged with the option named and give a non-zero exit.
#pragma once

namespace colmap {

int RunSphereBundleAdjuster(int argc, char** argv);

}  // namespace colmap
