"""Files interchange between SPHERA and unpatched upstream COLMAP 4.x at the
same commit, in both directions: databases (features and verified matches
written by one program are mapped by the other) and models (text and binary,
with PINHOLE, EUCM and EQUIRECTANGULAR cameras), and COLMAP 3.10 databases
(whose pose priors upstream cannot migrate) open in SPHERA with every row.

Needs the unpatched program that ../shared/peers/build_colmap4.sh builds
(SPHERA_UPSTREAM_COLMAP, default ~/.cache/sphera-peers/colmap4/build/...);
the upstream directions are skipped, saying so, without it."""
import os
import sqlite3
import struct
import sys
import unittest

from cli_util import SKIP_EXIT_CODE, Database, TempDirTestCase, require_render
from sphera_common import (UPSTREAM_COLMAP, extract_features,
                           match_exhaustive, read_text_model, run_colmap,
                           run_program, run_render)

UPSTREAM = os.environ.get("SPHERA_UPSTREAM_COLMAP", UPSTREAM_COLMAP)
HAVE_UPSTREAM = os.path.exists(UPSTREAM)
NEEDS_UPSTREAM = unittest.skipUnless(
    HAVE_UPSTREAM,
    f"unpatched upstream COLMAP not at {UPSTREAM}: build it with "
    "../shared/peers/build_colmap4.sh (or set SPHERA_UPSTREAM_COLMAP)")


def run_upstream(*args):
    return run_program(UPSTREAM, *args, name="upstream colmap")


def write_text_model(path):
    """Three cameras both programs know (ids, parameters and conventions are
    shared), three images and two points."""
    os.makedirs(path)
    with open(os.path.join(path, "cameras.txt"), "w") as f:
        f.write("1 PINHOLE 640 480 500 510 320 240\n"
                "2 EUCM 800 800 260.5 261.25 400.5 399.5 0.55 1.05\n"
                "3 EQUIRECTANGULAR 2048 1024 2048 1024\n")
    with open(os.path.join(path, "images.txt"), "w") as f:
        f.write("1 1 0 0 0 0 0 0 1 a.jpg\n"
                "100 200 1 300 300 -1\n"
                "2 0.6 0 0.8 0 0.5 0 0.1 2 b.jpg\n"
                "400.25 400.75 1 10 10 2\n"
                "3 0 1 0 0 -0.5 0.2 0 3 c.jpg\n"
                "1024.5 512.5 1 1024.5 100 2\n")
    with open(os.path.join(path, "points3D.txt"), "w") as f:
        f.write("1 0.1 0.2 3.0 10 20 30 0.5 1 0 2 0 3 0\n"
                "2 -1 0.5 2.5 40 50 60 0.25 2 1 3 1\n")


def model_summary(path):
    """Cameras, image poses and tracks of a text model, for comparison."""
    cameras, images, points = read_text_model(path)
    return (cameras,
            {i: (fields[1:10], obs) for i, (fields, obs) in images.items()},
            points)


# COLMAP 3.10's database schema (src/colmap/scene/database.cc of 3.10):
# pose priors without a covariance, no rigs and frames.
COLMAP310_SCHEMA = """
CREATE TABLE cameras (camera_id INTEGER PRIMARY KEY AUTOINCREMENT NOT NULL,
  model INTEGER NOT NULL, width INTEGER NOT NULL, height INTEGER NOT NULL,
  params BLOB, prior_focal_length INTEGER NOT NULL);
CREATE TABLE images (image_id INTEGER PRIMARY KEY AUTOINCREMENT NOT NULL,
  name TEXT NOT NULL UNIQUE, camera_id INTEGER NOT NULL,
  CONSTRAINT image_id_check CHECK(image_id >= 0 and image_id < 2147483647),
  FOREIGN KEY(camera_id) REFERENCES cameras(camera_id));
CREATE TABLE pose_priors (image_id INTEGER PRIMARY KEY NOT NULL,
  position BLOB, coordinate_system INTEGER NOT NULL,
  FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE);
CREATE TABLE keypoints (image_id INTEGER PRIMARY KEY NOT NULL,
  rows INTEGER NOT NULL, cols INTEGER NOT NULL, data BLOB,
  FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE);
CREATE TABLE descriptors (image_id INTEGER PRIMARY KEY NOT NULL,
  rows INTEGER NOT NULL, cols INTEGER NOT NULL, data BLOB,
  FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE);
CREATE TABLE matches (pair_id INTEGER PRIMARY KEY NOT NULL,
  rows INTEGER NOT NULL, cols INTEGER NOT NULL, data BLOB);
CREATE TABLE two_view_geometries (pair_id INTEGER PRIMARY KEY NOT NULL,
  rows INTEGER NOT NULL, cols INTEGER NOT NULL, data BLOB,
  config INTEGER NOT NULL, F BLOB, E BLOB, H BLOB, qvec BLOB, tvec BLOB);
CREATE UNIQUE INDEX index_name ON images(name);
"""


def write_colmap310_database(path, num_images=3, num_keypoints=50):
    """A COLMAP 3.10 database: one EUCM camera, NUM_IMAGES images with
    keypoints, descriptors, matches and verified geometries between
    consecutive images, and a pose prior (no covariance) for each image."""
    connection = sqlite3.connect(path)
    connection.executescript(COLMAP310_SCHEMA)
    connection.execute(
        "INSERT INTO cameras VALUES (1, 16, 800, 800, ?, 0)",
        (struct.pack("6d", 260, 260, 400, 400, 0.6, 1.1),))
    for image_id in range(1, num_images + 1):
        connection.execute("INSERT INTO images VALUES (?, ?, 1)",
                           (image_id, f"img{image_id}.jpg"))
        keypoints = struct.pack(f"{num_keypoints * 6}f", *(
            float(v) for k in range(num_keypoints)
            for v in (k * 7 % 800, k * 13 % 800, 1, 0, 0, 1)))
        connection.execute("INSERT INTO keypoints VALUES (?, ?, 6, ?)",
                           (image_id, num_keypoints, keypoints))
        descriptors = bytes((image_id + k) % 256
                            for k in range(num_keypoints * 128))
        connection.execute("INSERT INTO descriptors VALUES (?, ?, 128, ?)",
                           (image_id, num_keypoints, descriptors))
        connection.execute(
            "INSERT INTO pose_priors VALUES (?, ?, 1)",
            (image_id, struct.pack("3d", image_id, 2.0 * image_id, 0.5)))
    for image_id in range(1, num_images):
        pair_id = image_id * 2147483647 + image_id + 1
        matches = struct.pack(f"{2 * 20}I", *(
            v for k in range(20) for v in (k, k + 1)))
        connection.execute("INSERT INTO matches VALUES (?, 20, 2, ?)",
                           (pair_id, matches))
        connection.execute(
            "INSERT INTO two_view_geometries (pair_id, rows, cols, data, "
            "config) VALUES (?, 20, 2, ?, 2)", (pair_id, matches))
    connection.execute("PRAGMA user_version = 3900")  # as COLMAP 3.10 writes
    connection.commit()
    connection.close()


def database_counts(path):
    database = Database(path)
    counts = {table: database.scalar(f"SELECT COUNT(*) FROM {table}")
              for table in ("cameras", "images", "keypoints", "descriptors",
                            "matches", "two_view_geometries", "pose_priors")}
    counts["keypoint_rows"] = database.scalar("SELECT SUM(rows) FROM keypoints")
    counts["match_rows"] = database.scalar("SELECT SUM(rows) FROM matches")
    counts["verified_rows"] = database.scalar(
        "SELECT SUM(rows) FROM two_view_geometries")
    database.close()
    return counts


class InterchangeTest(TempDirTestCase):
    def convert(self, program, input_path, output_path, output_type):
        os.makedirs(output_path)
        program("model_converter", "--input_path", input_path,
                "--output_path", output_path, "--output_type", output_type)

    def check_model_round_trip(self, writer, reader):
        """WRITER converts a text model to binary, READER converts it back."""
        write_text_model(self.path("txt"))
        self.convert(writer, self.path("txt"), self.path("bin"), "BIN")
        self.convert(reader, self.path("bin"), self.path("txt2"), "TXT")
        expected = model_summary(self.path("txt"))
        actual = model_summary(self.path("txt2"))
        self.assertEqual(actual[0], expected[0])  # cameras, exactly
        self.assertEqual(sorted(actual[1]), sorted(expected[1]))
        for image_id, (fields, observations) in expected[1].items():
            actual_fields, actual_observations = actual[1][image_id]
            self.assertEqual(actual_fields[7:], fields[7:])  # camera, name
            for a, b in zip(actual_fields[:7], fields[:7]):
                self.assertAlmostEqual(float(a), float(b), places=9)
            self.assertEqual(actual_observations, observations)
        self.assertEqual({k: v[1] for k, v in actual[2].items()},
                         {k: v[1] for k, v in expected[2].items()})

    def test_models_sphera_text_to_binary_and_back(self):
        self.check_model_round_trip(run_colmap, run_colmap)

    @NEEDS_UPSTREAM
    def test_models_from_sphera_open_upstream(self):
        self.check_model_round_trip(run_colmap, run_upstream)

    @NEEDS_UPSTREAM
    def test_models_from_upstream_open_in_sphera(self):
        self.check_model_round_trip(run_upstream, run_colmap)

    def render_panoramas(self):
        scene = self.path("room")
        run_render(scene, "--seed", "3", "--layout", "room9", "--model",
                   "EQUIRECTANGULAR", "--width", "1024", "--height", "512",
                   "--supersample", "2")
        return os.path.join(scene, "images")

    def features_and_matches(self, program, images, database):
        extract_features(database, images, "EQUIRECTANGULAR",
                         program=program)
        match_exhaustive(database, program=program)

    def mapped_images(self, program, images, database, name):
        output = self.path(name)
        os.makedirs(output)
        program("mapper", "--database_path", database, "--image_path", images,
                "--output_path", output)
        self.convert(program, os.path.join(output, "0"), output + "_txt",
                     "TXT")
        _, registered, _ = read_text_model(output + "_txt")
        return len(registered)

    @NEEDS_UPSTREAM
    def test_databases_both_directions(self):
        images = self.render_panoramas()
        upstream_db = self.path("upstream.db")
        self.features_and_matches(run_upstream, images, upstream_db)
        before = database_counts(upstream_db)
        self.assertEqual(
            self.mapped_images(run_colmap, images, upstream_db, "sphera"), 9)
        after = database_counts(upstream_db)
        self.assertEqual(after, before)

        sphera_db = self.path("sphera.db")
        self.features_and_matches(run_colmap, images, sphera_db)
        self.assertEqual(
            self.mapped_images(run_upstream, images, sphera_db, "upstream"),
            9)

    def test_colmap310_database_opens_with_every_row(self):
        path = self.path("colmap310.db")
        write_colmap310_database(path)
        before = database_counts(path)
        # database_merger opens it (migrating the schema in place), reads
        # every table and writes them into a new database.
        run_colmap("database_creator", "--database_path", self.path("empty.db"))
        run_colmap("database_merger", "--database_path1", path,
                   "--database_path2", self.path("empty.db"),
                   "--merged_database_path", self.path("merged.db"))
        for migrated_path in (path, self.path("merged.db")):
            migrated = database_counts(migrated_path)
            self.assertEqual(migrated, before, migrated_path)
        database = Database(path)
        self.assertEqual(database.scalar("PRAGMA integrity_check"), "ok")
        self.assertEqual(database.scalar(
            "SELECT COUNT(*) FROM sqlite_master WHERE name = 'pose_priors_old'"),
            0)
        # The prior's position is kept; its covariance is unknown (NaN).
        position, covariance = database.connection.execute(
            "SELECT position, position_covariance FROM pose_priors "
            "WHERE corr_data_id = 2").fetchone()
        self.assertEqual(struct.unpack("3d", position), (2.0, 4.0, 0.5))
        values = struct.unpack("9d", covariance)
        self.assertTrue(all(v != v for v in values))
        database.close()


if __name__ == "__main__":
    require_render()
    if not HAVE_UPSTREAM:
        print(f"note: upstream COLMAP not at {UPSTREAM}; the tests against it "
              "are skipped (build it with ../shared/peers/build_colmap4.sh)")
    result = unittest.main(exit=False).result
    if not result.wasSuccessful():
        sys.exit(1)
    if result.testsRun == len(result.skipped):
        sys.exit(SKIP_EXIT_CODE)
