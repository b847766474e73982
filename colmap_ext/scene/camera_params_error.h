// Parameter checks of a camera with a message for the user.
#pragma once

#include "colmap/scene/camera.h"

#include <string>

namespace colmap {

// Empty when the camera's parameters are valid for its model and image size;
// otherwise a message naming the model and the offending parameter: SPHERA's
// checks (camera_models/) for the models it knows (EQUIRECTANGULAR: w = 2 h
// and w, h = the image size), else the parameter count, finite values and
// positive focal lengths.
std::string CameraParamsError(const Camera& camera);

}  // namespace colmap
