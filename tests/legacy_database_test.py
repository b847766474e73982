"""Databases from older COLMAP 3.x releases (legacy schema: `matches` +
`inlier_matches`, no `two_view_geometries`) open, migrate and keep every
keypoint, descriptor, match and verified geometry
(../shared/data/colmap_legacy, skipped without it)."""
import os
import shutil

from cli_util import SHARED_DATA, Database, TempDirTestCase, main_with_skip
from sphera_common import run_colmap

LEGACY = os.path.join(SHARED_DATA, "colmap_legacy")


def counts(database, geometry_table):
    return {
        "images": database.scalar("SELECT COUNT(*) FROM images"),
        "cameras": database.scalar("SELECT COUNT(*) FROM cameras"),
        "keypoints": database.scalar("SELECT SUM(rows) FROM keypoints"),
        "descriptors": database.scalar("SELECT SUM(rows) FROM descriptors"),
        "matches": database.scalar("SELECT SUM(rows) FROM matches"),
        "match_pairs": database.scalar(
            "SELECT COUNT(*) FROM matches WHERE rows > 0"),
        "verified": database.scalar(f"SELECT SUM(rows) FROM {geometry_table}"),
    }


class LegacyDatabaseTest(TempDirTestCase):
    def test_legacy_database_migrates_without_loss(self):
        legacy_path = self.path("legacy.db")
        shutil.copy(os.path.join(LEGACY, "database.db"), legacy_path)
        legacy = Database(legacy_path)
        before = counts(legacy, "inlier_matches")
        legacy.close()
        self.assertEqual(before["images"], 23)

        # database_merger opens the legacy database (migrating its schema in
        # place), reads every table and writes them into a new database.
        run_colmap("database_creator", "--database_path", self.path("empty.db"))
        run_colmap("database_merger", "--database_path1", legacy_path,
                   "--database_path2", self.path("empty.db"),
                   "--merged_database_path", self.path("merged.db"))

        migrated = Database(legacy_path)
        self.assertEqual(migrated.scalar("PRAGMA integrity_check"), "ok")
        self.assertEqual(counts(migrated, "two_view_geometries"), before)
        migrated.close()
        merged = Database(self.path("merged.db"))
        self.assertEqual(counts(merged, "two_view_geometries"), before)
        merged.close()

    def test_legacy_model_converts(self):
        os.makedirs(self.path("txt"))
        run_colmap("model_converter", "--input_path",
                   os.path.join(LEGACY, "sparse", "0"), "--output_path",
                   self.path("txt"), "--output_type", "TXT")
        with open(self.path("txt", "images.txt")) as f:
            header = [line for line in f if line.startswith("#")]
        self.assertTrue(any("Number of images: 23" in line for line in header))


if __name__ == "__main__":
    main_with_skip([LEGACY])
