#include "colmap_ext/sfm/rig_initial_pair.h"

#include "colmap/estimators/generalized_pose.h"
#include "colmap/feature/types.h"
#include "colmap/geometry/rigid3.h"
#include "colmap/geometry/triangulation.h"
#include "colmap/math/math.h"
#include "colmap/util/logging.h"

#include <algorithm>
#include <vector>

namespace colmap {
namespace {

const Frame& FrameOf(const DatabaseCache& database_cache, image_t image_id) {
  return database_cache.Frame(database_cache.Image(image_id).FrameId());
}

// The pose of `camera` in its rig: identity for the reference sensor.
Rigid3d CamFromRig(const Rig& rig, const Camera& camera) {
  return rig.IsRefSensor(camera.SensorId()) ? Rigid3d()
                                             : rig.SensorFromRig(camera.SensorId());
}

}  // namespace

bool IsRigFramePair(const DatabaseCache& database_cache,
                    const image_t image_id1,
                    const image_t image_id2) {
  for (const image_t image_id : {image_id1, image_id2}) {
    const Frame& frame = FrameOf(database_cache, image_id);
    if (database_cache.Rig(frame.RigId()).NumSensors() > 1) {
      return true;
    }
  }
  return false;
}

void MarkFramePairTried(const DatabaseCache& database_cache,
                        const image_t image_id1,
                        const image_t image_id2,
                        FlatHashSet<image_pair_t>* tried_pairs) {
  if (!IsRigFramePair(database_cache, image_id1, image_id2)) {
    return;
  }
  for (const data_t& data_id1 : FrameOf(database_cache, image_id1).ImageIds()) {
    for (const data_t& data_id2 :
         FrameOf(database_cache, image_id2).ImageIds()) {
      if (data_id1.id != data_id2.id) {
        tried_pairs->insert(ImagePairToPairId(data_id1.id, data_id2.id));
      }
    }
  }
}

std::optional<IncrementalMapperImpl::InitInfo> EstimateInitialRigFramePair(
    const IncrementalMapper::Options& options,
    const DatabaseCache& database_cache,
    const image_t image_id1,
    const image_t image_id2) {
  const Image& orig_image1 = database_cache.Image(image_id1);
  const Image& orig_image2 = database_cache.Image(image_id2);
  const Frame& frame1 = database_cache.Frame(orig_image1.FrameId());
  const Frame& frame2 = database_cache.Frame(orig_image2.FrameId());
  if (frame1.FrameId() == frame2.FrameId()) {
    return std::nullopt;
  }
  const Rig& rig1 = database_cache.Rig(frame1.RigId());
  const Rig& rig2 = database_cache.Rig(frame2.RigId());

  // The matches between all lenses of the two frames, as the generalized
  // solver takes them (one list of cameras for both frames).
  std::vector<Eigen::Vector2d> points2D1;
  std::vector<Eigen::Vector2d> points2D2;
  std::vector<size_t> camera_idxs1;
  std::vector<size_t> camera_idxs2;
  std::vector<Rigid3d> cams_from_rig;
  std::vector<Camera> cameras;
  FlatHashMap<camera_t, size_t> camera_idxs;
  const auto camera_idx = [&](const Rig& rig, const Camera& camera) {
    const auto [it, inserted] =
        camera_idxs.emplace(camera.camera_id, cameras.size());
    if (inserted) {
      cameras.push_back(camera);
      cams_from_rig.push_back(CamFromRig(rig, camera));
    }
    return it->second;
  };
  FeatureMatches matches;
  for (const data_t& data_id1 : frame1.ImageIds()) {
    const Image& image1 = database_cache.Image(data_id1.id);
    const size_t idx1 =
        camera_idx(rig1, database_cache.Camera(image1.CameraId()));
    for (const data_t& data_id2 : frame2.ImageIds()) {
      const Image& image2 = database_cache.Image(data_id2.id);
      const size_t idx2 =
          camera_idx(rig2, database_cache.Camera(image2.CameraId()));
      database_cache.CorrespondenceGraph()->ExtractMatchesBetweenImages(
          data_id1.id, data_id2.id, matches);
      for (const FeatureMatch& match : matches) {
        points2D1.push_back(image1.Point2D(match.point2D_idx1).xy);
        points2D2.push_back(image2.Point2D(match.point2D_idx2).xy);
        camera_idxs1.push_back(idx1);
        camera_idxs2.push_back(idx2);
      }
    }
  }
  if (static_cast<int>(points2D1.size()) < options.init_min_num_inliers) {
    return std::nullopt;
  }

  RANSACOptions ransac_options;
  ransac_options.min_num_trials = 30;
  ransac_options.random_seed = options.random_seed;
  ransac_options.max_error = options.init_max_error;
  std::optional<Rigid3d> rig2_from_rig1;
  std::optional<Rigid3d> pano2_from_pano1;
  size_t num_inliers = 0;
  std::vector<char> inlier_mask;
  if (!EstimateGeneralizedRelativePose(ransac_options,
                                       points2D1,
                                       points2D2,
                                       camera_idxs1,
                                       camera_idxs2,
                                       cams_from_rig,
                                       cameras,
                                       &rig2_from_rig1,
                                       &pano2_from_pano1,
                                       &num_inliers,
                                       &inlier_mask) ||
      static_cast<int>(num_inliers) < options.init_min_num_inliers) {
    return std::nullopt;
  }
  // Lenses that share one centre (a rig config without offsets) form a
  // panorama, whose motion comes up to scale.
  if (!rig2_from_rig1.has_value()) {
    rig2_from_rig1 = pano2_from_pano1;
  }
  if (!rig2_from_rig1.has_value()) {
    return std::nullopt;
  }

  // The triangulation angles of the inliers, each in its lens pair's frame
  // (upstream's mid-point triangulation; 0 for a point behind a lens).
  std::vector<double> angles;
  angles.reserve(num_inliers);
  for (size_t i = 0; i < inlier_mask.size(); ++i) {
    if (!inlier_mask[i]) {
      continue;
    }
    const std::optional<Eigen::Vector3d> cam_ray1 =
        cameras[camera_idxs1[i]].CamRayFromImg(points2D1[i]);
    const std::optional<Eigen::Vector3d> cam_ray2 =
        cameras[camera_idxs2[i]].CamRayFromImg(points2D2[i]);
    if (!cam_ray1 || !cam_ray2) {
      continue;
    }
    const Rigid3d cam2_from_cam1 = cams_from_rig[camera_idxs2[i]] *
                                   *rig2_from_rig1 *
                                   Inverse(cams_from_rig[camera_idxs1[i]]);
    Eigen::Vector3d point3D_in_cam1;
    angles.push_back(
        TriangulateMidPoint(cam2_from_cam1,
                            cam_ray1->normalized(),
                            cam_ray2->normalized(),
                            &point3D_in_cam1)
            ? CalculateTriangulationAngle(Eigen::Vector3d::Zero(),
                                          Inverse(cam2_from_cam1).translation(),
                                          point3D_in_cam1)
            : 0.0);
  }
  // A 360° rig sees far directions too, whose rays barely converge: the pair
  // is stable when enough inliers triangulate at a wide angle, whatever the
  // median (upstream's test of a single camera's pair).
  const double min_angle = DegToRad(options.init_min_tri_angle);
  const int num_wide = static_cast<int>(std::count_if(
      angles.begin(), angles.end(), [min_angle](const double angle) {
        return angle > min_angle;
      }));
  std::nth_element(
      angles.begin(), angles.begin() + angles.size() / 2, angles.end());
  VLOG(2) << "Initial rig frame pair " << frame1.FrameId() << ", "
          << frame2.FrameId() << ": " << num_inliers << " inliers of "
          << points2D1.size() << ", " << num_wide << " above "
          << options.init_min_tri_angle << " deg, median "
          << (angles.empty() ? 0.0 : RadToDeg(angles[angles.size() / 2]))
          << " deg";
  if (num_wide < options.init_min_num_inliers) {
    return std::nullopt;
  }

  IncrementalMapperImpl::InitInfo info;
  info.image_id1 = image_id1;
  info.image_id2 = image_id2;
  info.cam2_from_cam1 =
      CamFromRig(rig2, database_cache.Camera(orig_image2.CameraId())) *
      *rig2_from_rig1 *
      Inverse(CamFromRig(rig1, database_cache.Camera(orig_image1.CameraId())));
  return info;
}

double InitialTriangulationMinAngle(const IncrementalMapper::Options& options,
                                    const double min_angle,
                                    const Reconstruction& reconstruction,
                                    const image_t image_id1) {
  const Frame& frame = *reconstruction.Image(image_id1).FramePtr();
  return frame.RigPtr()->NumSensors() > 1 ? min_angle
                                          : options.init_min_tri_angle;
}

}  // namespace colmap
