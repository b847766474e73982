#include "estimators/similarity_alignment.h"

#include <cmath>
#include <limits>

#include <Eigen/Geometry>

namespace sphera {
namespace {

Eigen::Vector3d LogRotation(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd angle_axis(R);
  return angle_axis.angle() * angle_axis.axis();
}

Eigen::Matrix3d ExpRotation(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle == 0) {
    return Eigen::Matrix3d::Identity();
  }
  return Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

double SumOfGeodesicDistances(const Eigen::Matrix3d& R,
                              const std::vector<Eigen::Matrix3d>& rotations) {
  double sum = 0;
  for (const Eigen::Matrix3d& rotation : rotations) {
    sum += LogRotation(R.transpose() * rotation).norm();
  }
  return sum;
}

}  // namespace

Eigen::Matrix3d GeodesicMedianRotation(
    const std::vector<Eigen::Matrix3d>& rotations) {
  if (rotations.empty()) {
    return Eigen::Matrix3d::Identity();
  }
  // Start at the medoid: the data rotation with the least summed distance.
  Eigen::Matrix3d R = rotations[0];
  double best_sum = std::numeric_limits<double>::max();
  for (const Eigen::Matrix3d& candidate : rotations) {
    const double sum = SumOfGeodesicDistances(candidate, rotations);
    if (sum < best_sum) {
      best_sum = sum;
      R = candidate;
    }
  }

  constexpr int kMaxIterations = 100;
  constexpr double kCoincident = 1e-12;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    Eigen::Vector3d unit_sum = Eigen::Vector3d::Zero();
    double weight_sum = 0;
    int num_coincident = 0;
    for (const Eigen::Matrix3d& rotation : rotations) {
      const Eigen::Vector3d v = LogRotation(R.transpose() * rotation);
      const double norm = v.norm();
      if (norm < kCoincident) {
        ++num_coincident;
        continue;
      }
      unit_sum += v / norm;
      weight_sum += 1 / norm;
    }
    // At a data point the (sub)gradient of the sum of distances contains
    // zero iff the pull of the others does not exceed the coincident count.
    if (weight_sum == 0 || unit_sum.norm() <= num_coincident) {
      break;
    }
    // Weiszfeld step sum_i (v_i / |v_i|) / sum_i (1 / |v_i|), damped as in
    // Vardi and Zhang when the current point is on the data.
    Eigen::Vector3d step = unit_sum / weight_sum;
    if (num_coincident > 0) {
      step *= 1 - num_coincident / unit_sum.norm();
    }
    R = R * ExpRotation(step);
    if (step.norm() < 1e-15) {
      break;
    }
  }
  return R;
}

bool AlignCentersWithRotation(const std::vector<Eigen::Vector3d>& src_centers,
                              const std::vector<Eigen::Vector3d>& tgt_centers,
                              const Eigen::Matrix3d& tgt_from_src_rotation,
                              double* tgt_from_src_scale,
                              Eigen::Vector3d* tgt_from_src_translation) {
  const size_t n = src_centers.size();
  if (n < 2 || tgt_centers.size() != n) {
    return false;
  }
  Eigen::Vector3d src_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d tgt_mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    src_mean += src_centers[i];
    tgt_mean += tgt_centers[i];
  }
  src_mean /= n;
  tgt_mean /= n;
  // min_s sum |q_i - s R p_i|^2 over centred points: s = sum q.Rp / sum |p|^2.
  double numerator = 0;
  double denominator = 0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p =
        tgt_from_src_rotation * (src_centers[i] - src_mean);
    numerator += (tgt_centers[i] - tgt_mean).dot(p);
    denominator += p.squaredNorm();
  }
  if (!(denominator > 0) || !(numerator > 0)) {
    return false;
  }
  *tgt_from_src_scale = numerator / denominator;
  *tgt_from_src_translation =
      tgt_mean - *tgt_from_src_scale * tgt_from_src_rotation * src_mean;
  return true;
}

}  // namespace sphera
