// sphera_lens_fit: fits camera models to checkerboard corners (FitLens).
//
//   sphera_lens_fit [--circle_radius PX] CORNERS_FILE MODEL_NAME
//                   [MODEL_NAME ...]
//
// CORNERS_FILE is text; '#' starts a comment line. The first other line is
// the image size "width height", then one line per detected corner:
//   image_index board_x board_y board_z pixel_x pixel_y
// with image_index from 0, the board point in the board's plane (board_z = 0,
// any unit) and the pixel in COLMAP's convention (the centre of the upper-left
// pixel is (0.5, 0.5)).
//
// Prints per model one "key value" line each: model, status, rms_px, max_px,
// num_observations, num_not_visible, params (comma-separated, the model's
// parameter order), image_rms_px (per image), errors_px (per corner in the
// file's order, -1 where not visible), initial_focal, initial
// (own|equidistant), skipped_images, max_corner_angle_deg (the largest angle
// between a corner's ray and the optical axis, by the fitted board poses),
// circle_angle_deg (with --circle_radius: the mean angle from the axis of the
// fitted model's rays at that radius from the principal point, in four
// directions; how the fit extrapolates to a lens's image circle; nan outside
// the model's pixel domain), message; a blank line ends a model's block.
// Exit 1 with one line on stderr for a file or model name it cannot use.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "camera_models/registry.h"
#include "estimators/lens_fit.h"

namespace {

struct CornerFile {
  int width = 0;
  int height = 0;
  std::vector<sphera::BoardObservation> observations;
};

CornerFile ReadCornerFile(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error(path + ": cannot be opened");
  CornerFile corners;
  bool have_size = false;
  std::string line;
  int line_number = 0;
  while (std::getline(file, line)) {
    ++line_number;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream stream(line);
    const std::string where = path + ":" + std::to_string(line_number);
    std::string rest;
    if (!have_size) {
      if (!(stream >> corners.width >> corners.height) || (stream >> rest) ||
          corners.width <= 0 || corners.height <= 0) {
        throw std::runtime_error(where +
                                 ": expected the image size \"width height\" "
                                 "(two positive integers)");
      }
      have_size = true;
      continue;
    }
    sphera::BoardObservation observation;
    if (!(stream >> observation.image_index >> observation.point_in_board.x() >>
          observation.point_in_board.y() >> observation.point_in_board.z() >>
          observation.pixel.x() >> observation.pixel.y()) ||
        (stream >> rest)) {
      throw std::runtime_error(
          where +
          ": expected \"image_index board_x board_y board_z pixel_x "
          "pixel_y\"");
    }
    if (observation.image_index < 0 ||
        !observation.point_in_board.allFinite() ||
        !observation.pixel.allFinite()) {
      throw std::runtime_error(
          where + ": a negative image index or a non-finite number");
    }
    corners.observations.push_back(observation);
  }
  if (!have_size) throw std::runtime_error(path + ": no image size line");
  if (corners.observations.empty()) {
    throw std::runtime_error(path + ": no corners");
  }
  return corners;
}

double MaxCornerAngleDeg(const sphera::LensFitResult& result,
                         const CornerFile& corners) {
  double max_angle = 0;
  for (size_t i = 0; i < corners.observations.size(); ++i) {
    if (result.observation_errors_px[i] < 0) continue;
    const sphera::BoardObservation& observation = corners.observations[i];
    const Eigen::Vector3d point_in_cam =
        result.cam_from_board_rotations[observation.image_index] *
            observation.point_in_board +
        result.cam_from_board_translations[observation.image_index];
    max_angle = std::max(
        max_angle, std::atan2(point_in_cam.head<2>().norm(), point_in_cam.z()));
  }
  return max_angle * 180 / M_PI;
}

double AngleAtRadiusDeg(const sphera::LensFitResult& result, double radius_px) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector2d center;
  const bool has_center =
      sphera::internal::VisitModel(result.model_id, [&](auto model) {
        using Model = decltype(model);
        if constexpr (Model::kPrincipalPointIdxs.size() == 2) {
          center =
              Eigen::Vector2d(result.params[Model::kPrincipalPointIdxs[0]],
                              result.params[Model::kPrincipalPointIdxs[1]]);
          return true;
        }
        return false;
      });
  if (!has_center || result.params.empty()) return nan;
  double sum = 0;
  for (const Eigen::Vector2d direction :
       {Eigen::Vector2d(1, 0), Eigen::Vector2d(-1, 0), Eigen::Vector2d(0, 1),
        Eigen::Vector2d(0, -1)}) {
    Eigen::Vector3d ray;
    if (!sphera::RayFromImage(result.model_id, result.params,
                              center + radius_px * direction, &ray)) {
      return nan;
    }
    sum += std::atan2(ray.head<2>().norm(), ray.z());
  }
  return sum / 4 * 180 / M_PI;
}

void PrintResult(const sphera::LensFitResult& result, const CornerFile& corners,
                 double circle_radius_px) {
  std::printf("model %s\n", result.model_name.c_str());
  std::printf("status %s\n", sphera::LensFitStatusName(result.status));
  std::printf("rms_px %.6f\n", result.rms_error_px);
  std::printf("max_px %.6f\n", result.max_error_px);
  std::printf("num_observations %d\n", result.num_observations);
  std::printf("num_not_visible %d\n", result.num_not_visible);
  std::printf("params ");
  for (size_t i = 0; i < result.params.size(); ++i) {
    std::printf("%s%.10g", i > 0 ? "," : "", result.params[i]);
  }
  std::printf("\nimage_rms_px ");
  for (size_t i = 0; i < result.image_rms_error_px.size(); ++i) {
    std::printf("%s%.4f", i > 0 ? "," : "", result.image_rms_error_px[i]);
  }
  std::printf("\nerrors_px ");
  for (size_t i = 0; i < result.observation_errors_px.size(); ++i) {
    std::printf("%s%.4f", i > 0 ? "," : "", result.observation_errors_px[i]);
  }
  std::printf("\ninitial_focal %.3f\n", result.initial_focal_length);
  std::printf("initial %s\n",
              result.initial_from_equidistant ? "equidistant" : "own");
  std::printf("skipped_images ");
  for (size_t i = 0; i < result.skipped_images.size(); ++i) {
    std::printf("%s%d", i > 0 ? "," : "", result.skipped_images[i]);
  }
  std::printf("\nmax_corner_angle_deg %.2f\n",
              MaxCornerAngleDeg(result, corners));
  if (circle_radius_px > 0) {
    std::printf("circle_angle_deg %.2f\n",
                AngleAtRadiusDeg(result, circle_radius_px));
  }
  std::printf("message %s\n\n", result.message.c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  double circle_radius_px = 0;
  int first = 1;
  if (argc > 2 && std::string(argv[1]) == "--circle_radius") {
    char* end = nullptr;
    circle_radius_px = std::strtod(argv[2], &end);
    if (end == argv[2] || *end != '\0' || !(circle_radius_px > 0) ||
        !std::isfinite(circle_radius_px)) {
      std::cerr << "sphera_lens_fit: --circle_radius " << argv[2]
                << " is not a positive number of pixels\n";
      return 1;
    }
    first = 3;
  }
  if (argc - first < 2) {
    std::cerr << "usage: sphera_lens_fit [--circle_radius PX] CORNERS_FILE "
                 "MODEL_NAME [MODEL_NAME ...]\n";
    return 1;
  }
  try {
    std::vector<int> model_ids;
    for (int i = first + 1; i < argc; ++i) {
      const int id = sphera::ModelIdFromName(argv[i]);
      if (id < 0) {
        throw std::runtime_error(std::string("unknown camera model name ") +
                                 argv[i]);
      }
      model_ids.push_back(id);
    }
    const CornerFile corners = ReadCornerFile(argv[first]);
    for (int id : model_ids) {
      PrintResult(sphera::FitLens(id, corners.width, corners.height,
                                  corners.observations),
                  corners, circle_radius_px);
    }
  } catch (const std::exception& error) {
    std::cerr << "sphera_lens_fit: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
