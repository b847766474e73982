"""Two-view geometry on rays for a real-format pair: the two rendered Sponza
panoramas of the shared data set (../shared/data/equirect_pair, not in the
repository: the test is skipped without it) are verified as a calibrated pair
on the sphere and reconstructed by the mapper from that pair alone."""
import os
import unittest

from cli_util import SHARED_DATA, Database, TempDirTestCase, main_with_skip
from sphera_common import (analyze_model, extract_features,
                           match_exhaustive, run_colmap)

IMAGES = os.path.join(SHARED_DATA, "equirect_pair")


class EquirectPairTest(TempDirTestCase):
    def test_pair_is_verified_on_the_sphere_and_reconstructed(self):
        database_path = self.path("database.db")
        extract_features(database_path, IMAGES, "EQUIRECTANGULAR")
        match_exhaustive(database_path)
        database = Database(database_path)
        self.assertEqual(len(database.images()), 2)
        (camera,) = database.cameras().values()
        self.assertEqual(camera, (17, 2048, 1024, [2048.0, 1024.0]))
        config, num_inliers = database.connection.execute(
            "SELECT config, rows FROM two_view_geometries").fetchone()
        num_matches = database.scalar("SELECT rows FROM matches")
        database.close()
        # Calibrated (essential matrix on rays), most matches kept.
        self.assertEqual(config, 2)
        self.assertGreater(num_inliers, 300)
        self.assertGreater(num_inliers, 0.5 * num_matches)

        # COLMAP 4.x's mapper ignores tracks seen in two images only, also
        # when triangulating the initial pair: a set of two images needs
        # them (as with perspective images in upstream COLMAP).
        os.makedirs(self.path("sparse"))
        run_colmap("mapper", "--database_path", database_path,
                   "--image_path", IMAGES, "--output_path", self.path("sparse"),
                   "--Mapper.tri_ignore_two_view_tracks", "0")
        registered, points, reprojection_px = analyze_model(
            self.path("sparse", "0"))
        print(f"equirect_pair: {num_inliers}/{num_matches} inlier matches, "
              f"{points} points, mean reprojection error "
              f"{reprojection_px:.3f} px")
        self.assertEqual(registered, 2)
        self.assertGreater(points, 0.5 * num_inliers)
        self.assertLess(reprojection_px, 1.0)


if __name__ == "__main__":
    main_with_skip([IMAGES])
