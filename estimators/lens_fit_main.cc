// sphera_lens_fit: fits camera models to checkerboard corners (FitLens).
//
//   sphera_lens_fit CORNERS_FILE MODEL_NAME [MODEL_NAME ...]
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
// (own|equidistant), skipped_images, message; a blank line ends a model's
// block. Exit 1 with one line on stderr
// for a file or model name it cannot use.
#include <cstdio>
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

void PrintResult(const sphera::LensFitResult& result) {
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
  std::printf("\nmessage %s\n\n", result.message.c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: sphera_lens_fit CORNERS_FILE MODEL_NAME "
                 "[MODEL_NAME ...]\n";
    return 1;
  }
  try {
    std::vector<int> model_ids;
    for (int i = 2; i < argc; ++i) {
      const int id = sphera::ModelIdFromName(argv[i]);
      if (id < 0) {
        throw std::runtime_error(std::string("unknown camera model name ") +
                                 argv[i]);
      }
      model_ids.push_back(id);
    }
    const CornerFile corners = ReadCornerFile(argv[1]);
    for (int id : model_ids) {
      PrintResult(sphera::FitLens(id, corners.width, corners.height,
                                  corners.observations));
    }
  } catch (const std::exception& error) {
    std::cerr << "sphera_lens_fit: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
