#include "estimators/similarity_alignment.h"

#include <algorithm>
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

namespace {

double Median(std::vector<double> values) {
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) {
    return upper;
  }
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + mid));
}

}  // namespace

bool AlignViaSharedRigFrames(const std::vector<SharedRigFrame>& frames,
                             const int min_points,
                             const double fallback_scale,
                             SharedFrameAlignment* alignment) {
  if (frames.empty()) {
    return false;
  }
  std::vector<double> log_ratios;
  std::vector<Eigen::Matrix3d> rotations;
  for (const SharedRigFrame& frame : frames) {
    rotations.push_back(frame.tgt_rotation.transpose() * frame.src_rotation);
    for (const auto& [src_point, tgt_point] : frame.src_tgt_points) {
      const double src_distance =
          (frame.src_rotation * src_point + frame.src_translation).norm();
      const double tgt_distance =
          (frame.tgt_rotation * tgt_point + frame.tgt_translation).norm();
      // A point at the frame's origin (to rounding) carries no scale.
      const double src_tiny = 1e-12 * (1 + frame.src_translation.norm());
      const double tgt_tiny = 1e-12 * (1 + frame.tgt_translation.norm());
      if (src_distance > src_tiny && tgt_distance > tgt_tiny &&
          std::isfinite(src_distance) && std::isfinite(tgt_distance)) {
        log_ratios.push_back(std::log(tgt_distance / src_distance));
      }
    }
  }
  if (log_ratios.empty() || static_cast<int>(log_ratios.size()) < min_points) {
    if (!(fallback_scale > 0) || !std::isfinite(fallback_scale)) {
      return false;
    }
    alignment->scale = fallback_scale;
    alignment->num_points = 0;
    alignment->log_scale_spread = 0;
  } else {
    const double log_scale = Median(log_ratios);
    std::vector<double> deviations;
    for (const double log_ratio : log_ratios) {
      deviations.push_back(std::abs(log_ratio - log_scale));
    }
    alignment->scale = std::exp(log_scale);
    alignment->num_points = static_cast<int>(log_ratios.size());
    alignment->log_scale_spread = Median(deviations);
  }
  alignment->rotation = GeodesicMedianRotation(rotations);
  // A frame's centre c = -R^T t in each model: c_tgt = s R c_src + t.
  Eigen::Vector3d translation_sum = Eigen::Vector3d::Zero();
  for (const SharedRigFrame& frame : frames) {
    const Eigen::Vector3d src_center =
        -frame.src_rotation.transpose() * frame.src_translation;
    const Eigen::Vector3d tgt_center =
        -frame.tgt_rotation.transpose() * frame.tgt_translation;
    translation_sum +=
        tgt_center - alignment->scale * alignment->rotation * src_center;
  }
  alignment->translation = translation_sum / frames.size();
  return true;
}

}  // namespace sphera
