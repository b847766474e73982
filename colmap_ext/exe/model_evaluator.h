// `colmap model_evaluator --gt_path GT --input_path MODEL [--output_path DIR]
//     [--depth_path DEPTH] [--max_proj_center_error E]`: prints the errors of
// MODEL against the ground truth GT (controllers/model_evaluation.h) and
// writes evaluation.json and evaluation_images.csv to DIR.
#pragma once

namespace colmap {

int RunModelEvaluator(int argc, char** argv);

}  // namespace colmap
