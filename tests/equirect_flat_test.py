"""Feature extraction, exhaustive matching and mapping on the 11 real Ricoh
Theta S panoramas of the shared data set (../shared/data/equirect_flat/images, not in
the repository: the test is skipped without it)."""
import os
import unittest

from cli_util import SHARED_DATA, Database, TempDirTestCase, main_with_skip
from sphera_common import (analyze_model, extract_features,
                           match_exhaustive, run_colmap)

IMAGES = os.path.join(SHARED_DATA, "equirect_flat", "images")


class EquirectFlatTest(TempDirTestCase):
    def test_reconstruct_with_equirectangular_model(self):
        database_path = self.path("database.db")
        extract_features(database_path, IMAGES, "EQUIRECTANGULAR",
                         single_camera=False)
        database = Database(database_path)
        images = database.images()
        self.assertEqual(len(images), 11)
        cameras = database.cameras()
        for camera_id in set(images.values()):
            self.assertEqual(cameras[camera_id],
                             (17, 5376, 2688, [5376.0, 2688.0]))
        keypoints = database.num_keypoints()
        self.assertEqual(len(keypoints), 11)
        for name, count in keypoints.items():
            self.assertGreater(count, 2000, name)
        database.close()

        match_exhaustive(database_path)
        database = Database(database_path)
        num_pairs = database.scalar("SELECT COUNT(*) FROM matches")
        self.assertEqual(num_pairs, 55)
        num_matched = database.scalar(
            "SELECT COUNT(*) FROM matches WHERE rows > 100")
        self.assertGreater(num_matched, 10)
        # Verified on rays: calibrated two-view geometry (config 2).
        num_calibrated = database.scalar(
            "SELECT COUNT(*) FROM two_view_geometries WHERE config = 2")
        self.assertGreater(num_calibrated, 40)
        database.close()

        os.makedirs(self.path("sparse"))
        run_colmap("mapper", "--database_path", database_path,
                   "--image_path", IMAGES, "--output_path", self.path("sparse"))
        self.assertEqual(os.listdir(self.path("sparse")), ["0"])
        registered, points, reprojection_px = analyze_model(
            self.path("sparse", "0"))
        print(f"equirect_flat: {registered}/11 registered, {points} points, "
              f"mean reprojection error {reprojection_px:.3f} px")
        self.assertEqual(registered, 11)
        self.assertGreater(points, 3000)
        self.assertLess(reprojection_px, 1.0)


if __name__ == "__main__":
    main_with_skip([IMAGES])
