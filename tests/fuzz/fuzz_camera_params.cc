// libFuzzer target: the check of --ImageReader.camera_model and
// --ImageReader.camera_params that feature_extraction runs before any
// image (colmap_ext/controllers/image_errors.cc, with the per-model
// parameter checks of colmap_ext/scene/camera_params_error.cc). The input
// is "MODEL\nPARAMS"; parameters that pass are checked again against an
// image size taken from the input, as for each image.
#include "colmap/scene/camera.h"
#include "colmap/sensor/models.h"
#include "colmap_ext/controllers/image_errors.h"
#include "colmap_ext/scene/camera_params_error.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const size_t newline = input.find('\n');
  const std::string model = input.substr(0, newline);
  const std::string params =
      newline == std::string::npos ? "" : input.substr(newline + 1);
  if (!colmap::ImageReaderCameraOptionsError(model, params).empty() ||
      params.empty()) {
    return 0;
  }
  colmap::Camera camera;
  camera.model_id = colmap::CameraModelNameToId(model);
  camera.width = 1 + data[0] * 16;
  camera.height = 1 + data[size - 1] * 8;
  for (const std::string& value : colmap::StringSplit(params, ",;")) {
    char* end = nullptr;
    const double number = std::strtod(value.c_str(), &end);
    if (end != value.c_str()) {
      camera.params.push_back(number);
    }
  }
  colmap::CameraParamsError(camera);
  return 0;
}
