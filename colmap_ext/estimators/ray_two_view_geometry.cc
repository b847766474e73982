#include "colmap_ext/estimators/ray_two_view_geometry.h"

#include "colmap/geometry/triangulation.h"
#include "colmap/math/math.h"
#include "colmap/optim/loransac.h"
#include "colmap/util/logging.h"
#include "estimators/relative_pose.h"

namespace colmap {
namespace {

// Rays of the matches whose pixels both have a ray; match_idxs maps back.
struct MatchedRays {
  std::vector<Eigen::Vector3d> rays1;
  std::vector<Eigen::Vector3d> rays2;
  std::vector<size_t> match_idxs;
};

MatchedRays LiftMatches(const Camera& camera1,
                        const std::vector<Eigen::Vector2d>& points1,
                        const Camera& camera2,
                        const std::vector<Eigen::Vector2d>& points2,
                        const FeatureMatches& matches) {
  MatchedRays matched;
  matched.rays1.reserve(matches.size());
  matched.rays2.reserve(matches.size());
  matched.match_idxs.reserve(matches.size());
  Eigen::Vector3d ray1;
  Eigen::Vector3d ray2;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (camera1.CamRayFromImg(points1[matches[i].point2D_idx1], &ray1) &&
        camera2.CamRayFromImg(points2[matches[i].point2D_idx2], &ray2)) {
      matched.rays1.push_back(ray1);
      matched.rays2.push_back(ray2);
      matched.match_idxs.push_back(i);
    }
  }
  return matched;
}

FeatureMatches SelectMatches(const FeatureMatches& matches,
                             const std::vector<size_t>& match_idxs,
                             const std::vector<char>& inlier_mask) {
  FeatureMatches selected;
  for (size_t i = 0; i < inlier_mask.size(); ++i) {
    if (inlier_mask[i]) {
      selected.push_back(matches[match_idxs[i]]);
    }
  }
  return selected;
}

}  // namespace

bool UseRayTwoViewGeometry(const Camera& camera1, const Camera& camera2) {
  return CameraModelIsSphere(camera1.model_id) ||
         CameraModelIsSphere(camera2.model_id);
}

TwoViewGeometry EstimateRayTwoViewGeometry(
    const Camera& camera1,
    const std::vector<Eigen::Vector2d>& points1,
    const Camera& camera2,
    const std::vector<Eigen::Vector2d>& points2,
    const FeatureMatches& matches,
    const TwoViewGeometryOptions& options) {
  THROW_CHECK(options.Check());

  TwoViewGeometry geometry;
  geometry.config = TwoViewGeometry::ConfigurationType::DEGENERATE;
  const size_t min_num_inliers = static_cast<size_t>(options.min_num_inliers);
  if (matches.size() < min_num_inliers) {
    return geometry;
  }
  const MatchedRays matched =
      LiftMatches(camera1, points1, camera2, points2, matches);
  if (matched.rays1.size() < min_num_inliers) {
    return geometry;
  }

  // The pixel threshold becomes an angle per camera.
  RANSACOptions ray_ransac_options = options.ransac_options;
  ray_ransac_options.max_error =
      (camera1.CamRayFromImgThreshold(options.ransac_options.max_error) +
       camera2.CamRayFromImgThreshold(options.ransac_options.max_error)) /
      2;

  LORANSAC<sphera::EssentialMatrixRayEstimator,
           sphera::EssentialMatrixRayEstimator>
      E_ransac(ray_ransac_options);
  const auto E_report = E_ransac.Estimate(matched.rays1, matched.rays2);

  LORANSAC<sphera::RotationOnlyEstimator, sphera::RotationOnlyEstimator>
      rotation_ransac(ray_ransac_options);
  const auto rotation_report =
      rotation_ransac.Estimate(matched.rays1, matched.rays2);

  const bool E_ok =
      E_report.success && E_report.support.num_inliers >= min_num_inliers;
  const bool rotation_ok = rotation_report.success &&
                           rotation_report.support.num_inliers >=
                               min_num_inliers;
  if (!E_ok && !rotation_ok) {
    return geometry;
  }

  // As COLMAP's H/E test: when a pure rotation explains (almost) as many
  // matches as the essential matrix, the baseline is not observable.
  const bool panoramic =
      !E_ok || static_cast<double>(rotation_report.support.num_inliers) >
                   options.max_H_inlier_ratio * E_report.support.num_inliers;
  if (panoramic) {
    geometry.config = TwoViewGeometry::ConfigurationType::PANORAMIC;
    geometry.inlier_matches = SelectMatches(
        matches, matched.match_idxs, rotation_report.inlier_mask);
    geometry.cam2_from_cam1 =
        Rigid3d(Eigen::Quaterniond(rotation_report.model),
                Eigen::Vector3d::Zero());
  } else {
    geometry.config = TwoViewGeometry::ConfigurationType::CALIBRATED;
    geometry.E = E_report.model;
    geometry.inlier_matches =
        SelectMatches(matches, matched.match_idxs, E_report.inlier_mask);
  }

  if (options.compute_relative_pose) {
    EstimateRayTwoViewGeometryPose(
        camera1, points1, camera2, points2, &geometry);
  }
  return geometry;
}

bool EstimateRayTwoViewGeometryPose(const Camera& camera1,
                                    const std::vector<Eigen::Vector2d>& points1,
                                    const Camera& camera2,
                                    const std::vector<Eigen::Vector2d>& points2,
                                    TwoViewGeometry* geometry) {
  const bool calibrated =
      geometry->config == TwoViewGeometry::ConfigurationType::CALIBRATED;
  const bool panoramic =
      geometry->config == TwoViewGeometry::ConfigurationType::PANORAMIC;
  if (!calibrated && !panoramic) {
    return false;
  }
  const MatchedRays inliers = LiftMatches(
      camera1, points1, camera2, points2, geometry->inlier_matches);
  if (inliers.rays1.size() < 2) {
    return false;
  }

  if (panoramic) {
    std::vector<Eigen::Matrix3d> rotations;
    sphera::RotationOnlyEstimator::Estimate(
        inliers.rays1, inliers.rays2, &rotations);
    if (rotations.empty()) {
      return false;
    }
    geometry->cam2_from_cam1 = Rigid3d(Eigen::Quaterniond(rotations[0]),
                                       Eigen::Vector3d::Zero());
    geometry->tri_angle = 0;
    return true;
  }

  Eigen::Matrix3d cam2_from_cam1_rotation;
  Eigen::Vector3d cam2_from_cam1_translation;
  std::vector<Eigen::Vector3d> points3D;
  const size_t num_in_front =
      sphera::RelativePoseFromEssential(geometry->E,
                                        inliers.rays1,
                                        inliers.rays2,
                                        /*inlier_mask=*/{},
                                        &cam2_from_cam1_rotation,
                                        &cam2_from_cam1_translation,
                                        &points3D);
  if (num_in_front == 0) {
    return false;
  }
  geometry->cam2_from_cam1 =
      Rigid3d(Eigen::Quaterniond(cam2_from_cam1_rotation),
              cam2_from_cam1_translation);
  geometry->tri_angle = Median(CalculateTriangulationAngles(
      Eigen::Vector3d::Zero(),
      -cam2_from_cam1_rotation.transpose() * cam2_from_cam1_translation,
      points3D));
  return true;
}

}  // namespace colmap
