#include "colmap_ext/scene/points_at_camera_center.h"

#include "colmap/scene/synthetic.h"

#include <gtest/gtest.h>

namespace colmap {
namespace {

Reconstruction Panoramas() {
  SyntheticDatasetOptions options;
  options.num_rigs = 1;
  options.num_frames_per_rig = 3;
  options.num_points3D = 50;
  options.camera_width = 1024;
  options.camera_height = 512;
  options.camera_model_id = CameraModelId::kEquirectangular;
  options.camera_params = {1024, 512};
  Reconstruction reconstruction;
  SynthesizeDataset(options, &reconstruction);
  return reconstruction;
}

TEST(PointsAtCameraCenter, APointAtACentreIsFound) {
  Reconstruction reconstruction = Panoramas();
  const double min_distance = MinDistanceFromSphericalCenter(reconstruction);
  EXPECT_GT(min_distance, 0);
  const image_t image_id = *reconstruction.RegImageIds().begin();
  const Image& image = reconstruction.Image(image_id);
  EXPECT_TRUE(
      ObservationsAtCenter(reconstruction, image, min_distance).empty());

  point2D_t observed = 0;
  while (!image.Point2D(observed).HasPoint3D()) {
    ++observed;
  }
  reconstruction.Point3D(image.Point2D(observed).point3D_id).xyz =
      image.ProjectionCenter();
  EXPECT_EQ(ObservationsAtCenter(reconstruction, image, min_distance),
            std::vector<point2D_t>{observed});
}

TEST(PointsAtCameraCenter, APointSeenTwiceByAnImageIsListedOnce) {
  Reconstruction reconstruction = Panoramas();
  const double min_distance = MinDistanceFromSphericalCenter(reconstruction);
  const image_t image_id = *reconstruction.RegImageIds().begin();
  const Image& image = reconstruction.Image(image_id);
  point2D_t observed = 0;
  while (!image.Point2D(observed).HasPoint3D()) {
    ++observed;
  }
  point2D_t free = 0;
  while (image.Point2D(free).HasPoint3D()) {
    ++free;
  }
  ASSERT_LT(free, image.NumPoints2D());
  const point3D_t point3D_id = image.Point2D(observed).point3D_id;
  reconstruction.AddObservation(point3D_id, TrackElement(image_id, free));
  reconstruction.Point3D(point3D_id).xyz = image.ProjectionCenter();
  EXPECT_EQ(ObservationsAtCenter(reconstruction, image, min_distance).size(),
            1);
}

TEST(PointsAtCameraCenter, PerspectiveCamerasAreNotMeasured) {
  SyntheticDatasetOptions options;
  options.num_rigs = 1;
  options.num_frames_per_rig = 3;
  Reconstruction reconstruction;
  SynthesizeDataset(options, &reconstruction);
  EXPECT_EQ(MinDistanceFromSphericalCenter(reconstruction), 0);
}

}  // namespace
}  // namespace colmap
