#include "colmap_ext/scene/points_at_camera_center.h"

#include "colmap/math/math.h"

#include <unordered_set>

namespace colmap {

double MinDistanceFromSphericalCenter(const Reconstruction& reconstruction) {
  constexpr double kMinDistanceRatio = 1e-3;
  std::vector<double> distances;
  for (const frame_t frame_id : reconstruction.RegFrameIds()) {
    for (const data_t& data_id : reconstruction.Frame(frame_id).ImageIds()) {
      const Image& image = reconstruction.Image(data_id.id);
      if (!image.CameraPtr()->IsSpherical()) {
        continue;
      }
      const Eigen::Vector3d center = image.ProjectionCenter();
      for (const Point2D& point2D : image.Points2D()) {
        if (point2D.HasPoint3D()) {
          distances.push_back(
              (reconstruction.Point3D(point2D.point3D_id).xyz - center).norm());
        }
      }
    }
  }
  return distances.empty() ? 0 : kMinDistanceRatio * Median(distances);
}

std::vector<point2D_t> ObservationsAtCenter(const Reconstruction& reconstruction,
                                            const Image& image,
                                            const double min_distance) {
  std::vector<point2D_t> at_center;
  // One observation per point: a track may hold two of one image, and
  // deleting one of a two-element track deletes the point.
  std::unordered_set<point3D_t> listed;
  const Eigen::Vector3d center = image.ProjectionCenter();
  for (point2D_t point2D_idx = 0; point2D_idx < image.NumPoints2D();
       ++point2D_idx) {
    const Point2D& point2D = image.Point2D(point2D_idx);
    if (point2D.HasPoint3D() &&
        (reconstruction.Point3D(point2D.point3D_id).xyz - center).norm() <
            min_distance &&
        listed.insert(point2D.point3D_id).second) {
      at_center.push_back(point2D_idx);
    }
  }
  return at_center;
}

}  // namespace colmap
