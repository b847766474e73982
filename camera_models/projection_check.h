// Whether a camera's parameters give a usable projection over its image:
// the per-parameter checks of each model (CheckParams) say nothing of values
// that are each allowed but together leave a projection that cannot be
// inverted over the image (a distortion so strong that the inverse does not
// converge, values so large that rays are not finite). This samples the
// image and asks of every pixel that has a ray that the ray is finite and
// projects back onto the pixel, and along lines from the principal point
// that the angle to the axis grows with the distance (a projection that
// folds maps two angles to one radius).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera_models/fold.h"
#include "camera_models/registry.h"

namespace sphera {

namespace internal {

// Where a camera's field ends on the segment from `inside` (a pixel with a
// ray) to `outside` (one without): the last pixel with a ray, found by
// bisection to the precision of doubles, its unit ray and the ray's angle
// to the axis.
struct FieldEnd {
  Eigen::Vector2d pixel;
  Eigen::Vector3d ray;
  double angle;
};

inline FieldEnd FindFieldEnd(int model_id, const std::vector<double>& params,
                             Eigen::Vector2d inside, Eigen::Vector2d outside) {
  Eigen::Vector3d ray;
  RayFromImage(model_id, params, inside, &ray);
  for (int i = 0; i < 64; ++i) {
    const Eigen::Vector2d middle = 0.5 * (inside + outside);
    if (middle == inside || middle == outside) break;
    Eigen::Vector3d middle_ray;
    if (RayFromImage(model_id, params, middle, &middle_ray) &&
        middle_ray.allFinite() && middle_ray.norm() > 0) {
      inside = middle;
      ray = middle_ray;
    } else {
      outside = middle;
    }
  }
  ray.normalize();
  return {inside, ray, std::acos(std::clamp(ray.z(), -1.0, 1.0))};
}

// Whether the model projects to a finite pixel a ray turned 0.01°, 0.1° or
// 1° further from the axis than `ray` (in the plane of `ray` and the axis):
// then the model's field goes on past `ray`.
inline bool ProjectsBeyond(int model_id, const std::vector<double>& params,
                           const Eigen::Vector3d& ray) {
  const double angle = std::acos(std::clamp(ray.z(), -1.0, 1.0));
  const double azimuth =
      std::hypot(ray.x(), ray.y()) > 0 ? std::atan2(ray.y(), ray.x()) : 0.0;
  for (const double turn_deg : {0.01, 0.1, 1.0}) {
    const double beyond = angle + turn_deg * M_PI / 180;
    if (beyond >= M_PI) break;
    const Eigen::Vector3d turned(std::sin(beyond) * std::cos(azimuth),
                                 std::sin(beyond) * std::sin(azimuth),
                                 std::cos(beyond));
    Eigen::Vector2d pixel;
    if (ImageFromRay(model_id, params, turned, &pixel) && pixel.allFinite()) {
      return true;
    }
  }
  return false;
}

}  // namespace internal

// "" or why the projection of `model_id` with `params` is not usable over
// the width x height image. Pixels without a ray (outside a fisheye's image
// circle) are allowed; an image in which no sampled pixel has a ray is not.
// The parameters must have passed CheckParams.
inline std::string ProjectionOverImageError(int model_id,
                                            const std::vector<double>& params,
                                            int width, int height) {
  if (width <= 0 || height <= 0) return "";
  std::string name;
  internal::VisitModel(model_id, [&](auto model) {
    name = decltype(model)::kModelName;
  });
  const auto at = [](double x, double y) {
    return "(" + internal::FormatFixed(x, 1) + ", " +
           internal::FormatFixed(y, 1) + ")";
  };
  // Round trip within a thousandth of a pixel, or a millionth of the
  // pixel's distance from the origin for very large images.
  const auto round_trip_error = [&](const Eigen::Vector2d& pixel,
                                    double* angle) -> std::string {
    Eigen::Vector3d ray;
    *angle = -1;
    if (!RayFromImage(model_id, params, pixel, &ray)) return "";
    if (!ray.allFinite() || ray.norm() == 0) {
      return name + ": pixel " + at(pixel.x(), pixel.y()) +
             " of the " + std::to_string(width) + "x" +
             std::to_string(height) + " image has no finite ray";
    }
    *angle = std::acos(std::clamp(ray.normalized().z(), -1.0, 1.0));
    Eigen::Vector2d back;
    const bool visible = ImageFromRay(model_id, params, ray, &back);
    const double tolerance = std::max(1e-3, 1e-6 * pixel.norm());
    if (!visible || !back.allFinite() || (back - pixel).norm() > tolerance) {
      return name + ": the projection cannot be inverted at pixel " +
             at(pixel.x(), pixel.y()) + " of the " + std::to_string(width) +
             "x" + std::to_string(height) + " image (its ray projects to " +
             (visible && back.allFinite() ? at(back.x(), back.y())
                                          : std::string("no pixel")) +
             ")";
    }
    return "";
  };

  // Lines from the pixel of the optical axis (or the image point nearest
  // it) to the border: where pixels have rays, the angle to the axis may not
  // fall as the distance grows.
  Eigen::Vector2d origin;
  if (!ImageFromRay(model_id, params, Eigen::Vector3d(0, 0, 1), &origin) ||
      !origin.allFinite()) {
    return name + ": the optical axis has no pixel";
  }
  if (origin.x() < -width || origin.x() > 2.0 * width ||
      origin.y() < -height || origin.y() > 2.0 * height) {
    return name + ": the optical axis projects to " +
           at(origin.x(), origin.y()) + ", far outside the " +
           std::to_string(width) + "x" + std::to_string(height) +
           " image (principal point wrong?)";
  }
  // From the image point nearest the axis pixel, the distance to it grows
  // along every line into the image (the image is convex).
  origin = origin.cwiseMax(Eigen::Vector2d(0, 0))
               .cwiseMin(Eigen::Vector2d(width, height));
  constexpr int kGrid = 16;
  int with_ray = 0;
  for (int i = 0; i <= kGrid; ++i) {
    for (int j = 0; j <= kGrid; ++j) {
      const Eigen::Vector2d pixel(width * (0.5 + i) / (kGrid + 1.0),
                                  height * (0.5 + j) / (kGrid + 1.0));
      double angle;
      if (std::string error = round_trip_error(pixel, &angle);
          !error.empty()) {
        return error;
      }
      with_ray += angle >= 0;
    }
  }
  if (with_ray == 0) {
    return name + ": no pixel of the " + std::to_string(width) + "x" +
           std::to_string(height) + " image has a ray (principal point " +
           "or focal length far off?)";
  }

  // The equirectangular projection is not radial (its angle to the axis
  // falls again beyond 90° of longitude); its checks are exact (w = 2h).
  if (model_id == static_cast<int>(ModelId::kEquirectangular)) return "";
  constexpr int kLines = 12;
  constexpr int kSteps = 100;
  // How far from the axis pixel the field reaches on any line.
  double field_reach = 0;
  for (int line = 0; line < kLines; ++line) {
    const double phi = 2 * M_PI * line / kLines;
    const Eigen::Vector2d direction(std::cos(phi), std::sin(phi));
    double reach = 1e300;
    for (int axis = 0; axis < 2; ++axis) {
      const double size = axis == 0 ? width : height;
      if (direction[axis] > 1e-12) {
        reach = std::min(reach, (size - origin[axis]) / direction[axis]);
      } else if (direction[axis] < -1e-12) {
        reach = std::min(reach, -origin[axis] / direction[axis]);
      }
    }
    double previous = -1;
    Eigen::Vector2d previous_pixel = origin;
    for (int step = 0; step <= kSteps; ++step) {
      const Eigen::Vector2d pixel = origin + direction * reach * step / kSteps;
      double angle;
      if (std::string error = round_trip_error(pixel, &angle);
          !error.empty()) {
        return error;
      }
      if (angle < 0) {
        // A lens's field may end inside the image (a fisheye's circle). One
        // that ends before 90° from the axis is the model's own domain when
        // the model sees no ray beyond it (EUCM: r² <= 1 / (beta (2 alpha -
        // 1))), and a distortion whose inverse gives up when the model
        // still projects rays further out.
        if (previous >= 0 && previous < M_PI / 2) {
          const internal::FieldEnd end =
              internal::FindFieldEnd(model_id, params, previous_pixel, pixel);
          field_reach = std::max(field_reach, (end.pixel - origin).norm());
          if (end.angle < M_PI / 2 &&
              internal::ProjectsBeyond(model_id, params, end.ray)) {
            return name + ": the projection breaks off inside the " +
                   std::to_string(width) + "x" + std::to_string(height) +
                   " image: past pixel " + at(end.pixel.x(), end.pixel.y()) +
                   ", " + internal::FormatFixed(end.angle * 180 / M_PI, 2) +
                   "° from the axis, pixels have no ray though the model "
                   "projects rays further out (a distortion that cannot be "
                   "inverted there)";
          }
        }
        previous = -1;
        continue;
      }
      previous_pixel = pixel;
      field_reach = std::max(field_reach, (pixel - origin).norm());
      if (angle < previous - 1e-9) {
        return name + ": the projection folds inside the " +
               std::to_string(width) + "x" + std::to_string(height) +
               " image: towards pixel " + at(pixel.x(), pixel.y()) +
               " the angle to the axis falls from " +
               internal::FormatFixed(previous * 180 / M_PI, 2) + "° to " +
               internal::FormatFixed(angle * 180 / M_PI, 2) + "°";
      }
      previous = angle;
    }
  }
  if (field_reach < 1) {
    return name + ": the field of view covers less than a pixel around " +
           at(origin.x(), origin.y()) + " of the " + std::to_string(width) +
           "x" + std::to_string(height) +
           " image (focal length or distortion far off?)";
  }
  return "";
}

}  // namespace sphera
