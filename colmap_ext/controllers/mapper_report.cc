#include "colmap_ext/controllers/mapper_report.h"

#include "colmap_ext/scene/intrinsics_divergence.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>

#include "colmap/util/logging.h"

namespace colmap {

std::vector<MapperImageReport> BuildMapperReport(
    const Database& database,
    const ReconstructionManager& reconstruction_manager,
    const int min_num_matches,
    const std::vector<std::string>& image_name_list) {
  const std::unordered_set<std::string> image_names(image_name_list.begin(),
                                                    image_name_list.end());
  std::unordered_map<std::string, int> model_of_name;
  for (size_t k = 0; k < reconstruction_manager.Size(); ++k) {
    const auto& reconstruction = *reconstruction_manager.Get(k);
    for (const image_t image_id : reconstruction.RegImageIds()) {
      model_of_name.emplace(reconstruction.Image(image_id).Name(),
                            static_cast<int>(k));
    }
  }

  std::unordered_map<image_t, std::pair<size_t, int>> pair_stats;
  for (const auto& [pair_id, num_inliers] :
       database.ReadTwoViewGeometryNumInliers()) {
    const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
    for (const image_t image_id : {image_id1, image_id2}) {
      auto& [num_pairs, max_inliers] = pair_stats[image_id];
      max_inliers = std::max(max_inliers, num_inliers);
      if (num_inliers >= min_num_matches) ++num_pairs;
    }
  }

  std::vector<MapperImageReport> report;
  for (const Image& image : database.ReadAllImages()) {
    if (!image_names.empty() && image_names.count(image.Name()) == 0) {
      continue;
    }
    MapperImageReport entry;
    entry.name = image.Name();
    const auto model = model_of_name.find(image.Name());
    if (model != model_of_name.end()) entry.model_index = model->second;
    entry.num_keypoints = database.NumKeypointsForImage(image.ImageId());
    const auto stats = pair_stats.find(image.ImageId());
    if (stats != pair_stats.end()) {
      entry.num_verified_pairs = stats->second.first;
      entry.max_inlier_matches = stats->second.second;
    }
    if (entry.model_index < 0) {
      if (entry.num_keypoints == 0) {
        entry.reason = "no keypoints (too few features in the image)";
      } else if (entry.num_verified_pairs == 0) {
        entry.reason =
            "no verified image pair with at least " +
            std::to_string(min_num_matches) + " inlier matches (" +
            std::to_string(entry.num_keypoints) + " keypoints, at most " +
            std::to_string(entry.max_inlier_matches) +
            " inlier matches with another image)";
      } else {
        entry.reason =
            "verified pairs with " + std::to_string(entry.num_verified_pairs) +
            " image(s), but no model kept it (too few 2D-3D "
            "correspondences, no pose within the error threshold, or its "
            "group made a model smaller than --Mapper.min_model_size)";
      }
    }
    report.push_back(std::move(entry));
  }
  std::sort(report.begin(), report.end(),
            [](const MapperImageReport& a, const MapperImageReport& b) {
              return a.name < b.name;
            });
  return report;
}

void LogMapperReport(const Database& database,
                     const ReconstructionManager& reconstruction_manager,
                     const IncrementalPipelineOptions& mapper_options,
                     const std::vector<HeldCamera>& held_cameras) {
  const std::vector<MapperImageReport> report =
      BuildMapperReport(database,
                        reconstruction_manager,
                        mapper_options.min_num_matches,
                        mapper_options.image_names);
  size_t num_registered = 0;
  for (const MapperImageReport& entry : report) {
    if (entry.model_index >= 0) ++num_registered;
  }
  LOG(INFO) << "Mapper report: " << num_registered << " of " << report.size()
            << " images registered, in " << reconstruction_manager.Size()
            << " model(s)";
  for (size_t k = 0; k < reconstruction_manager.Size(); ++k) {
    const auto& reconstruction = *reconstruction_manager.Get(k);
    LOG(INFO) << "  model " << k << ": " << reconstruction.NumRegImages()
              << " images, " << reconstruction.NumPoints3D() << " points";
  }
  if (reconstruction_manager.Size() > 1) {
    LOG(WARNING) << "The images split into " << reconstruction_manager.Size()
                 << " models: the groups share too few verified matches to "
                    "be joined (more overlap, or sequential/vocabulary tree "
                    "matching with more neighbours, can connect them)";
  }
  for (const MapperImageReport& entry : report) {
    if (entry.model_index < 0) {
      LOG(WARNING) << entry.name << ": not registered: " << entry.reason;
    }
  }
  for (const HeldCamera& held : held_cameras) {
    LOG(WARNING) << "Camera " << held.camera.camera_id << " ("
                 << held.camera.ModelName()
                 << ") was held: its self-calibration ran away (" << held.reason
                 << "); it kept " << held.camera.ParamsToString()
                 << " (Mapper.hold_focal_ratio, Mapper.hold_aspect_change)";
  }
}

}  // namespace colmap
