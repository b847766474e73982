#include "colmap_ext/estimators/ray_absolute_pose.h"

#include "colmap/optim/loransac.h"
#include "colmap/util/logging.h"
#include "estimators/absolute_pose.h"

namespace colmap {

bool EstimateRayAbsolutePose(const AbsolutePoseEstimationOptions& options,
                             const std::vector<Eigen::Vector2d>& points2D,
                             const std::vector<Eigen::Vector3d>& points3D,
                             Rigid3d* cam_from_world,
                             const Camera& camera,
                             size_t* num_inliers,
                             std::vector<char>* inlier_mask) {
  THROW_CHECK_EQ(points2D.size(), points3D.size());
  options.Check();

  std::vector<Eigen::Vector3d> rays;
  std::vector<Eigen::Vector3d> ray_points3D;
  std::vector<size_t> idxs;
  rays.reserve(points2D.size());
  ray_points3D.reserve(points2D.size());
  idxs.reserve(points2D.size());
  Eigen::Vector3d ray_in_cam;
  for (size_t i = 0; i < points2D.size(); ++i) {
    if (camera.CamRayFromImg(points2D[i], &ray_in_cam)) {
      rays.push_back(ray_in_cam);
      ray_points3D.push_back(points3D[i]);
      idxs.push_back(i);
    }
  }

  *num_inliers = 0;
  inlier_mask->assign(points2D.size(), false);
  if (rays.size() < sphera::P3PRayEstimator::kMinNumSamples) {
    return false;
  }

  RANSACOptions ray_ransac_options = options.ransac_options;
  ray_ransac_options.max_error =
      camera.CamRayFromImgThreshold(options.ransac_options.max_error);
  LORANSAC<sphera::P3PRayEstimator, sphera::P3PRayEstimator> ransac(
      ray_ransac_options);
  const auto report = ransac.Estimate(rays, ray_points3D);
  if (!report.success) {
    return false;
  }

  *cam_from_world =
      Rigid3d(Eigen::Quaterniond(report.model.leftCols<3>()).normalized(),
              report.model.col(3));
  *num_inliers = report.support.num_inliers;
  for (size_t i = 0; i < idxs.size(); ++i) {
    (*inlier_mask)[idxs[i]] = report.inlier_mask[i];
  }
  return true;
}

}  // namespace colmap
