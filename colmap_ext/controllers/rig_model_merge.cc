#include "colmap_ext/controllers/rig_model_merge.h"

#include "colmap/estimators/alignment.h"
#include "colmap/sfm/observation_manager.h"
#include "colmap/util/file.h"
#include "colmap/util/logging.h"
#include "colmap/util/misc.h"
#include "colmap_ext/sfm/held_bundle_adjustment.h"

#include "estimators/similarity_alignment.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <unordered_set>
#include <utility>

namespace colmap {
namespace {

// The merged model must keep this share of the two models' observations
// through the point filter, and its mean reprojection error stay within this
// factor of the worse of the two, or the merge is undone: a wrong scale or a
// frame registered wrongly in one of them shows as points that no longer
// reproject.
constexpr double kMinKeptObservations = 0.8;
constexpr double kMaxReprojectionErrorGrowth = 1.5;
// ... plus this much [px], for models of (nearly) exact observations.
constexpr double kReprojectionErrorSlackPx = 0.1;

// 3D points of both models from the same keypoints of the shared frames
// that the scale needs: their median ratio survives two badly triangulated
// ones.
constexpr int kMinCommonPoints = 5;

sphera::SharedRigFrame CollectSharedFrame(const Reconstruction& src,
                                          const Reconstruction& tgt,
                                          const frame_t frame_id) {
  sphera::SharedRigFrame shared;
  const Rigid3d& src_rig_from_world = src.Frame(frame_id).RigFromWorld();
  const Rigid3d& tgt_rig_from_world = tgt.Frame(frame_id).RigFromWorld();
  shared.src_rotation = src_rig_from_world.rotation().toRotationMatrix();
  shared.src_translation = src_rig_from_world.translation();
  shared.tgt_rotation = tgt_rig_from_world.rotation().toRotationMatrix();
  shared.tgt_translation = tgt_rig_from_world.translation();
  for (const data_t& data_id : src.Frame(frame_id).ImageIds()) {
    if (!src.ExistsImage(data_id.id) || !tgt.ExistsImage(data_id.id)) {
      continue;
    }
    const Image& src_image = src.Image(data_id.id);
    const Image& tgt_image = tgt.Image(data_id.id);
    const point2D_t num_points2D =
        std::min(src_image.NumPoints2D(), tgt_image.NumPoints2D());
    for (point2D_t idx = 0; idx < num_points2D; ++idx) {
      const struct Point2D& src_point2D = src_image.Point2D(idx);
      const struct Point2D& tgt_point2D = tgt_image.Point2D(idx);
      if (src_point2D.HasPoint3D() && tgt_point2D.HasPoint3D()) {
        shared.src_tgt_points.emplace_back(
            src.Point3D(src_point2D.point3D_id).xyz,
            tgt.Point3D(tgt_point2D.point3D_id).xyz);
      }
    }
  }
  return shared;
}

// Keypoints with a 3D point in either model (those of a shared image
// counted once).
size_t NumObservedKeypoints(const Reconstruction& src,
                            const Reconstruction& tgt) {
  size_t num_observed = 0;
  for (const auto& [image_id, image] : tgt.Images()) {
    const Image* src_image =
        src.ExistsImage(image_id) ? &src.Image(image_id) : nullptr;
    for (point2D_t idx = 0; idx < image.NumPoints2D(); ++idx) {
      if (image.Point2D(idx).HasPoint3D() ||
          (src_image != nullptr && idx < src_image->NumPoints2D() &&
           src_image->Point2D(idx).HasPoint3D())) {
        ++num_observed;
      }
    }
  }
  for (const auto& [image_id, image] : src.Images()) {
    if (!tgt.ExistsImage(image_id)) {
      num_observed += image.NumPoints3D();
    }
  }
  return num_observed;
}

void RefineMergedModel(const IncrementalPipelineOptions& options,
                       const std::vector<HeldCamera>& held_cameras,
                       Reconstruction& reconstruction) {
  ObservationManager(reconstruction).FilterObservationsWithNegativeDepth();
  std::unordered_set<camera_t> held_ids;
  for (const HeldCamera& held : held_cameras) {
    held_ids.insert(held.camera.camera_id);
  }
  AdjustPosedImages(options.GlobalBundleAdjustment(), held_ids, reconstruction);
  ObservationManager(reconstruction)
      .FilterAllPoints3D(options.mapper.filter_max_reproj_error,
                         options.mapper.filter_min_tri_angle);
  reconstruction.UpdatePoint3DErrors();
}

// The ratio tgt / src of the lens offsets in the rigs of `frame_ids`
// (averaged over the lenses with an offset in both), 0 without any: the
// mapper ends each model at the rig config's scale, so this is the scale
// between them when no common point gives it.
double RigOffsetScale(const Reconstruction& src,
                      const Reconstruction& tgt,
                      const std::vector<frame_t>& frame_ids) {
  constexpr double kMinOffset = 1e-6;
  std::set<rig_t> rig_ids;
  for (const frame_t frame_id : frame_ids) {
    rig_ids.insert(src.Frame(frame_id).RigId());
  }
  double sum = 0;
  int count = 0;
  for (const rig_t rig_id : rig_ids) {
    if (!tgt.ExistsRig(rig_id)) {
      continue;
    }
    const Rig& src_rig = src.Rig(rig_id);
    const Rig& tgt_rig = tgt.Rig(rig_id);
    for (const auto& [sensor_id, src_from_rig] : src_rig.NonRefSensors()) {
      if (!src_from_rig.has_value() || !tgt_rig.HasSensorFromRig(sensor_id)) {
        continue;
      }
      const double src_offset = src_from_rig->translation().norm();
      const double tgt_offset =
          tgt_rig.SensorFromRig(sensor_id).translation().norm();
      if (src_offset > kMinOffset && tgt_offset > kMinOffset) {
        sum += tgt_offset / src_offset;
        ++count;
      }
    }
  }
  return count > 0 ? sum / count : 0;
}

}  // namespace

std::vector<frame_t> SharedRigFrames(const Reconstruction& reconstruction1,
                                     const Reconstruction& reconstruction2) {
  std::vector<frame_t> shared;
  for (const frame_t frame_id : reconstruction1.RegFrameIds()) {
    if (!reconstruction2.ExistsFrame(frame_id) ||
        !reconstruction2.Frame(frame_id).HasPose()) {
      continue;
    }
    const Frame& frame = reconstruction1.Frame(frame_id);
    if (reconstruction1.Rig(frame.RigId()).NumSensors() >= 2) {
      shared.push_back(frame_id);
    }
  }
  std::sort(shared.begin(), shared.end());
  return shared;
}

bool MergeRigModels(const IncrementalPipelineOptions& options,
                    const std::vector<HeldCamera>& held_cameras,
                    const int min_common_points,
                    const Reconstruction& src,
                    Reconstruction& tgt,
                    std::string* why) {
  const std::vector<frame_t> frame_ids = SharedRigFrames(src, tgt);
  if (frame_ids.empty()) {
    *why = "they share no frame of a rig with several sensors";
    return false;
  }
  std::vector<sphera::SharedRigFrame> frames;
  for (const frame_t frame_id : frame_ids) {
    frames.push_back(CollectSharedFrame(src, tgt, frame_id));
  }
  sphera::SharedFrameAlignment alignment;
  if (!sphera::AlignViaSharedRigFrames(frames,
                                       min_common_points,
                                       RigOffsetScale(src, tgt, frame_ids),
                                       &alignment)) {
    size_t num_points = 0;
    for (const sphera::SharedRigFrame& frame : frames) {
      num_points += frame.src_tgt_points.size();
    }
    *why = StringPrintf(
        "%d shared rig frame(s), but only %d 3D point(s) of both models from "
        "the same keypoints (%d needed for the scale) and no lens offsets "
        "in the rig",
        static_cast<int>(frames.size()),
        static_cast<int>(num_points),
        min_common_points);
    return false;
  }
  const Sim3d tgt_from_src(alignment.scale,
                           Eigen::Quaterniond(alignment.rotation),
                           alignment.translation);

  const double error_before = std::max(src.ComputeMeanReprojectionError(),
                                       tgt.ComputeMeanReprojectionError());
  const size_t observations_before = NumObservedKeypoints(src, tgt);
  Reconstruction merged = tgt;
  if (!MergeReconstructions(tgt_from_src, src, merged)) {
    *why = "the models' images do not correspond (different databases?)";
    return false;
  }
  RefineMergedModel(options, held_cameras, merged);
  // Back to the scale the mapper left tgt at (the rig config's, when the
  // rig has lens offsets), which the bundle adjustment's gauge does not
  // keep.
  AlignReconstructionToOrigRigScales(tgt.Rigs(), &merged);
  const size_t observations_after = merged.ComputeNumObservations();
  const double error_after = merged.ComputeMeanReprojectionError();
  if (observations_after < kMinKeptObservations * observations_before ||
      !(error_after <= kMaxReprojectionErrorGrowth * error_before +
                           kReprojectionErrorSlackPx)) {
    *why = StringPrintf(
        "merged through %d shared rig frame(s) and %d common points, the "
        "model does not hold together: %d of %d observations kept, mean "
        "reprojection error %.3f px (the models' own: up to %.3f px)",
        static_cast<int>(frames.size()),
        alignment.num_points,
        static_cast<int>(observations_after),
        static_cast<int>(observations_before),
        error_after,
        error_before);
    return false;
  }
  const std::string scale_source =
      alignment.num_points > 0
          ? StringPrintf("%d common points (spread %.0f%%)",
                         alignment.num_points,
                         100 * (std::exp(alignment.log_scale_spread) - 1))
          : std::string("the rig's lens offsets");
  LOG(INFO) << StringPrintf(
      "=> Merged through %d shared rig frame(s): scale %.4g from %s, %d "
      "observations, %.3f px",
      static_cast<int>(frames.size()),
      alignment.scale,
      scale_source.c_str(),
      static_cast<int>(observations_after),
      error_after);
  tgt = merged;
  return true;
}

size_t MergeModelsSharingRigFrames(
    const IncrementalPipelineOptions& options,
    const std::vector<HeldCamera>& held_cameras,
    const std::filesystem::path& output_path,
    const size_t num_written,
    ReconstructionManager& reconstruction_manager) {
  size_t num_merges = 0;
  // Pairs (tgt, src) of models tried and refused, by address: a model's
  // address stays while others are deleted from the manager.
  std::set<std::pair<const Reconstruction*, const Reconstruction*>> refused;
  bool merged = true;
  while (merged && reconstruction_manager.Size() > 1) {
    merged = false;
    std::vector<size_t> order(reconstruction_manager.Size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return reconstruction_manager.Get(a)->NumRegImages() >
             reconstruction_manager.Get(b)->NumRegImages();
    });
    for (size_t i = 0; i < order.size() && !merged; ++i) {
      for (size_t j = i + 1; j < order.size() && !merged; ++j) {
        Reconstruction& tgt = *reconstruction_manager.Get(order[i]);
        const Reconstruction& src = *reconstruction_manager.Get(order[j]);
        if (refused.count({&tgt, &src}) > 0 ||
            SharedRigFrames(src, tgt).empty()) {
          continue;
        }
        LOG(INFO) << StringPrintf(
            "Merging model %d (%d images) into model %d (%d images)",
            static_cast<int>(order[j]),
            static_cast<int>(src.NumRegImages()),
            static_cast<int>(order[i]),
            static_cast<int>(tgt.NumRegImages()));
        std::string why;
        if (MergeRigModels(options,
                           held_cameras,
                           kMinCommonPoints,
                           src,
                           tgt,
                           &why)) {
          reconstruction_manager.Delete(order[j]);
          ++num_merges;
          merged = true;
        } else {
          LOG(WARNING) << "Models " << order[i] << " and " << order[j]
                       << " share rig frames but were not merged: " << why;
          refused.insert({&tgt, &src});
        }
      }
    }
  }
  if (num_merges == 0) {
    return 0;
  }
  for (size_t i = 0; i < reconstruction_manager.Size(); ++i) {
    const std::filesystem::path path = output_path / std::to_string(i);
    CreateDirIfNotExists(path);
    reconstruction_manager.Get(i)->Write(path);
  }
  for (size_t i = reconstruction_manager.Size(); i < num_written; ++i) {
    std::filesystem::remove_all(output_path / std::to_string(i));
  }
  return num_merges;
}

}  // namespace colmap
