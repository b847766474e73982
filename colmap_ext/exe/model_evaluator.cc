#include "colmap_ext/exe/model_evaluator.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/util/file.h"
#include "colmap/util/logging.h"
#include "colmap_ext/controllers/model_evaluation.h"
#include "colmap_ext/util/file_output.h"

#include <iomanip>
#include <iostream>
#include <sstream>

namespace colmap {

int RunModelEvaluator(int argc, char** argv) {
  std::string gt_path;
  std::string input_path;
  std::string output_path;
  ModelEvaluationOptions evaluation_options;

  OptionManager options;
  options.AddRequiredOption("gt_path", &gt_path);
  options.AddRequiredOption("input_path", &input_path);
  options.AddDefaultOption("output_path", &output_path);
  options.AddDefaultOption("depth_path", &evaluation_options.depth_path);
  options.AddDefaultOption("max_proj_center_error",
                           &evaluation_options.max_proj_center_error);
  options.AddDefaultEnumOption("alignment",
                               &evaluation_options.alignment,
                               ModelAlignmentToString,
                               ModelAlignmentFromString,
                               "centers: least-squares similarity of the "
                               "camera centres; orientations: rotation from "
                               "the camera orientations");
  if (!options.Parse(argc, argv)) {
    return EXIT_FAILURE;
  }
  if (const std::string error = evaluation_options.Check(); !error.empty()) {
    LOG(ERROR) << "model_evaluator: " << error;
    return EXIT_FAILURE;
  }

  for (const auto& [name, path] :
       {std::make_pair("gt_path", gt_path),
        std::make_pair("input_path", input_path)}) {
    if (!ExistsDir(path)) {
      LOG(ERROR) << name << ": " << path << " is not a directory";
      return EXIT_FAILURE;
    }
  }
  if (!output_path.empty() && !ExistsDir(output_path)) {
    LOG(ERROR) << "output_path: " << output_path << " is not a directory";
    return EXIT_FAILURE;
  }

  ModelEvaluation evaluation;
  try {
    Reconstruction ground_truth;
    try {
      ground_truth.Read(gt_path);
    } catch (const std::exception& error) {
      throw std::invalid_argument("cannot read the ground truth " + gt_path +
                                  ": " + error.what());
    }
    Reconstruction reconstruction;
    try {
      reconstruction.Read(input_path);
    } catch (const std::exception& error) {
      throw std::invalid_argument("cannot read the model " + input_path +
                                  ": " + error.what());
    }
    evaluation = EvaluateModel(ground_truth, reconstruction, evaluation_options);
  } catch (const std::exception& error) {
    LOG(ERROR) << "model_evaluator: " << error.what();
    return EXIT_FAILURE;
  }

  std::ostringstream table;
  table << std::fixed;
  table << "image                          reg   rot_err_deg  pos_err      "
           "pos_err/baseline\n";
  for (const ImageEvaluation& image : evaluation.images) {
    table << std::left << std::setw(30) << image.name << " "
          << (image.registered ? "yes" : "no ") << "   ";
    if (image.registered) {
      table << std::setprecision(5) << std::setw(12)
            << image.rotation_error_deg << " " << std::setprecision(6)
            << std::setw(12) << image.position_error << " "
            << image.position_error_normalized;
    }
    table << "\n";
  }
  table << std::setprecision(6)
        << "alignment: " << AlignmentName(evaluation.alignment)
        << "\nregistered: " << evaluation.num_registered
        << "/" << evaluation.num_gt_images
        << "\nrotation error (deg): mean " << evaluation.mean_rotation_error_deg
        << " max " << evaluation.max_rotation_error_deg
        << "\nposition error: mean " << evaluation.mean_position_error
        << " max " << evaluation.max_position_error << " (mean "
        << evaluation.mean_position_error_normalized
        << " of the closest-pair baseline "
        << evaluation.closest_pair_baseline << ")"
        << "\nreprojection error: mean " << evaluation.mean_angular_error_rad
        << " rad = " << evaluation.mean_angular_error_px << " px over "
        << evaluation.num_observations << " observations\n";
  for (const CameraEvaluation& camera : evaluation.cameras) {
    table << "  camera " << camera.camera_id << " (" << camera.model_name
          << "): " << camera.mean_angular_error_rad << " rad = "
          << camera.mean_angular_error_px << " px\n";
  }
  if (evaluation.mean_point_error >= 0) {
    table << "3D point error: mean " << evaluation.mean_point_error
          << " median " << evaluation.median_point_error << " over "
          << evaluation.num_points_with_depth << " points\n";
  }
  std::cout << table.str() << std::flush;

  if (!output_path.empty()) {
    std::ostringstream csv;
    csv << std::setprecision(10)
        << "name,registered,rotation_error_deg,position_error,"
           "position_error_normalized\n";
    for (const ImageEvaluation& image : evaluation.images) {
      csv << image.name << "," << (image.registered ? 1 : 0) << ","
          << image.rotation_error_deg << "," << image.position_error << ","
          << image.position_error_normalized << "\n";
    }
    try {
      WriteTextFilesAtomically(
          output_path,
          {{"evaluation.json", ModelEvaluationToJson(evaluation)},
           {"evaluation_images.csv", csv.str()}});
    } catch (const std::exception& error) {
      LOG(ERROR) << "model_evaluator: " << error.what();
      return EXIT_FAILURE;
    }
  }
  return EXIT_SUCCESS;
}

}  // namespace colmap
