#include "estimators/rig_direction_check.h"

#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "estimators/similarity_alignment.h"

namespace sphera {
namespace {

double RotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

// A lens pair's measurements combined over frames, as lens2_from_lens1
// with lens1 < lens2.
struct CombinedPair {
  int lens1 = -1;
  int lens2 = -1;
  Eigen::Matrix3d cam2_from_cam1 = Eigen::Matrix3d::Identity();
  int num_measurements = 0;
  int num_inliers = 0;
  double disagreement_rad = 0;
};

}  // namespace

void RigDirectionCheckOptions::Check() const {
  if (!(max_disagreement_rad > 0 &&
        max_disagreement_rad <= 3.14159265358979323846)) {
    throw std::invalid_argument("max_disagreement_rad must be in (0, pi], got " +
                                std::to_string(max_disagreement_rad));
  }
}

std::vector<LensDirection> CheckRigDirections(
    const std::vector<Eigen::Matrix3d>& config_cam_from_rig,
    const std::vector<LensPairRotation>& measurements,
    const RigDirectionCheckOptions& options) {
  options.Check();
  const int num_lenses = static_cast<int>(config_cam_from_rig.size());
  std::map<std::pair<int, int>, std::vector<Eigen::Matrix3d>> per_pair;
  std::map<std::pair<int, int>, int> inliers_per_pair;
  for (const LensPairRotation& measurement : measurements) {
    if (measurement.lens1 < 0 || measurement.lens1 >= num_lenses ||
        measurement.lens2 < 0 || measurement.lens2 >= num_lenses ||
        measurement.lens1 == measurement.lens2) {
      throw std::invalid_argument(
          "CheckRigDirections: a measurement between lenses " +
          std::to_string(measurement.lens1) + " and " +
          std::to_string(measurement.lens2) + " of a rig of " +
          std::to_string(num_lenses) + " lenses");
    }
    const bool ordered = measurement.lens1 < measurement.lens2;
    const std::pair<int, int> key =
        ordered ? std::make_pair(measurement.lens1, measurement.lens2)
                : std::make_pair(measurement.lens2, measurement.lens1);
    per_pair[key].push_back(ordered ? measurement.cam2_from_cam1
                                    : Eigen::Matrix3d(measurement.cam2_from_cam1
                                                          .transpose()));
    inliers_per_pair[key] += measurement.num_inliers;
  }

  std::vector<CombinedPair> pairs;
  std::vector<LensDirection> lenses(num_lenses);
  for (const auto& [key, rotations] : per_pair) {
    CombinedPair pair;
    pair.lens1 = key.first;
    pair.lens2 = key.second;
    pair.cam2_from_cam1 = GeodesicMedianRotation(rotations);
    pair.num_measurements = static_cast<int>(rotations.size());
    pair.num_inliers = inliers_per_pair[key];
    pair.disagreement_rad = RotationAngle(
        pair.cam2_from_cam1, config_cam_from_rig[pair.lens2] *
                                 config_cam_from_rig[pair.lens1].transpose());
    for (const int lens : {pair.lens1, pair.lens2}) {
      LensDirection& direction = lenses[lens];
      direction.status = LensDirectionStatus::kConsistent;
      direction.num_pairs += 1;
      direction.num_measurements += pair.num_measurements;
      direction.num_inliers += pair.num_inliers;
      direction.max_pair_disagreement_rad =
          std::max(direction.max_pair_disagreement_rad, pair.disagreement_rad);
    }
    pairs.push_back(pair);
  }

  // Name lenses greedily until no pair among the others disagrees.
  std::vector<bool> named(num_lenses, false);
  while (true) {
    std::vector<int> num_pairs(num_lenses, 0), num_disagreeing(num_lenses, 0);
    std::vector<double> sum_disagreement(num_lenses, 0);
    for (const CombinedPair& pair : pairs) {
      if (named[pair.lens1] || named[pair.lens2]) {
        continue;
      }
      const bool disagrees =
          pair.disagreement_rad > options.max_disagreement_rad;
      for (const int lens : {pair.lens1, pair.lens2}) {
        num_pairs[lens] += 1;
        num_disagreeing[lens] += disagrees ? 1 : 0;
        sum_disagreement[lens] += disagrees ? pair.disagreement_rad : 0;
      }
    }
    int worst = -1;
    double worst_share = 0;
    for (int lens = 0; lens < num_lenses; ++lens) {
      if (num_disagreeing[lens] == 0) {
        continue;
      }
      const double share =
          static_cast<double>(num_disagreeing[lens]) / num_pairs[lens];
      // Later lenses win ties (>=): the first is usually the reference.
      if (worst < 0 || share > worst_share ||
          (share == worst_share &&
           sum_disagreement[lens] >= sum_disagreement[worst])) {
        worst = lens;
        worst_share = share;
      }
    }
    if (worst < 0) {
      break;
    }
    named[worst] = true;
    lenses[worst].status = LensDirectionStatus::kContradicted;
  }

  // Every lens's direction from its pairs with the consistent lenses.
  for (int lens = 0; lens < num_lenses; ++lens) {
    std::vector<Eigen::Matrix3d> estimates;
    for (const CombinedPair& pair : pairs) {
      if (pair.lens1 == lens && !named[pair.lens2]) {
        // cam1_from_rig = cam2_from_cam1^T cam2_from_rig
        estimates.push_back(pair.cam2_from_cam1.transpose() *
                            config_cam_from_rig[pair.lens2]);
      } else if (pair.lens2 == lens && !named[pair.lens1]) {
        estimates.push_back(pair.cam2_from_cam1 *
                            config_cam_from_rig[pair.lens1]);
      }
    }
    if (estimates.empty()) {
      continue;
    }
    LensDirection& direction = lenses[lens];
    direction.measured = true;
    direction.measured_cam_from_rig = GeodesicMedianRotation(estimates);
    direction.angle_off_rad = RotationAngle(direction.measured_cam_from_rig,
                                            config_cam_from_rig[lens]);
  }
  return lenses;
}

Eigen::Vector2d LensAxisAzimuthElevationDeg(
    const Eigen::Matrix3d& cam_from_ref) {
  const Eigen::Vector3d axis = cam_from_ref.transpose().col(2);
  const double deg_per_rad = 180 / M_PI;
  return {std::atan2(axis.x(), axis.z()) * deg_per_rad,
          std::atan2(-axis.y(), std::hypot(axis.x(), axis.z())) * deg_per_rad};
}

}  // namespace sphera
