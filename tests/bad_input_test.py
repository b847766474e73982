"""Bad input of every other kind than model files (bad_model_test.py has
those): damaged databases, images, option values, paths and killed runs,
through the commands that read them.

A rendered scene (16 small pinhole cameras of the renderer's ring) is extracted,
matched and mapped once; the corpus is made from it. Each case asserts its
outcome class. A clear error: exit code 1 (no signal, no abort), the
damaged file, image, option or path named in the output, no "Check failed",
"terminate called" or stack trace, and the input unchanged (a database's
tables and rows; its bytes when SQLite cannot read it). Success where the
input is valid. A killed run: the database still passes COLMAP's own check
and a second run completes the work, with every image extracted once and no
camera without an image.
"""
import hashlib
import os
import random
import shutil
import signal
import sqlite3
import struct
import subprocess
import tempfile
import time
import unittest

from cli_util import TempDirTestCase, require_render
from sphera_common import COLMAP, RENDER, read_text_cameras, run_colmap

NUM_IMAGES = 16  # the renderer's ring: one model with its true intrinsics
TIMEOUT_S = 180  # a hang, not a slow run: each command takes seconds
CPU = ["--FeatureExtraction.use_gpu", "0"]
CPU_MATCHING = ["--FeatureMatching.use_gpu", "0"]
# Signs of an abort rather than an error message.
ABORT_MARKERS = ("terminate called", "*** Aborted", "SIGSEGV", "SIGABRT",
                 "stack trace")
# And of garbage reaching COLMAP's internal checks (a database or an image
# that passed for valid). Option values are checked by COLMAP's option
# checks, which log "Check failed: <field> ..." before the error.
INTERNAL_CHECK = "Check failed"


def run_bounded(args, timeout=TIMEOUT_S):
    """(exit code or None on a hang, output) of `colmap ARGS`."""
    try:
        result = subprocess.run([COLMAP, *args], stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True,
                                errors="replace", timeout=timeout)
    except subprocess.TimeoutExpired as error:
        return None, f"no exit within {timeout} s: {error.output or ''}"
    return result.returncode, result.stdout


def database_state(path):
    """What a failed command must not change: the database's schema, rows
    and user_version as SQLite dumps them, or its bytes when SQLite cannot
    read it (or it does not exist)."""
    if not os.path.exists(path):
        return ("absent",)
    try:
        connection = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            version = connection.execute("PRAGMA user_version").fetchone()
            return ("rows", version, tuple(connection.iterdump()))
        finally:
            connection.close()
    except sqlite3.DatabaseError:
        with open(path, "rb") as f:
            return ("bytes", hashlib.sha256(f.read()).hexdigest())


def true_camera_params(scene):
    """The parameters of the single camera of SCENE's ground-truth model,
    as --ImageReader.camera_params."""
    cameras = read_text_cameras(os.path.join(scene, "sparse_gt"))
    if len(cameras) != 1:
        raise RuntimeError(f"{scene}: expected one camera, got {len(cameras)}")
    (_, _, _, params), = cameras.values()
    return ",".join(str(p) for p in params)


class Scene:
    """The rendered scene, its database after extraction and matching, and
    the mapper's model; made once for all tests."""
    root = None

    @classmethod
    def make(cls, root):
        cls.root = root
        cls.images = os.path.join(root, "scene", "images")
        subprocess.run([RENDER, "--output", os.path.join(root, "scene"),
                        "--layout", "ring", "--num_cameras", str(NUM_IMAGES),
                        "--width", "320", "--height", "240",
                        "--supersample", "1", "--seed", "3"],
                       check=True, capture_output=True)
        cls.extracted = os.path.join(root, "extracted.db")
        # The ring's true intrinsics: from COLMAP's default focal length
        # (2.4x the true one) the mapper splits the ring into several models
        # that vary from run to run, and one of them may be a broken merge.
        run_colmap("feature_extractor", "--database_path", cls.extracted,
                   "--image_path", cls.images, "--ImageReader.camera_model",
                   "PINHOLE", "--ImageReader.single_camera", "1",
                   "--ImageReader.camera_params",
                   true_camera_params(os.path.join(root, "scene")), *CPU)
        cls.database = os.path.join(root, "matched.db")
        shutil.copy(cls.extracted, cls.database)
        run_colmap("exhaustive_matcher", "--database_path", cls.database,
                   *CPU_MATCHING)
        cls.sparse = os.path.join(root, "sparse")
        os.makedirs(cls.sparse)
        run_colmap("mapper", "--database_path", cls.database, "--image_path",
                   cls.images, "--output_path", cls.sparse)
        cls.model = os.path.join(cls.sparse, "0")


def setUpModule():
    require_render()
    Scene.make(tempfile.mkdtemp(prefix="sphera_bad_input_"))


def tearDownModule():
    if Scene.root:
        shutil.rmtree(Scene.root, ignore_errors=True)


class BadInputCase(TempDirTestCase):
    def assert_named_error(self, code, output, names, case,
                           internal_checks=False):
        """Exit code 1, each of NAMES in the output, no sign of an abort
        (nor of an internal check unless INTERNAL_CHECKS)."""
        tail = output[-2500:]
        self.assertEqual(code, 1, f"{case}: exit {code}\n{tail}")
        for name in names:
            self.assertIn(name, output, f"{case}: {name!r} not named\n{tail}")
        markers = ABORT_MARKERS + (() if internal_checks else (INTERNAL_CHECK,))
        for marker in markers:
            self.assertNotIn(marker, output, f"{case}\n{tail}")

    def command_args(self, command, database, out):
        """The arguments of COMMAND on DATABASE, writing to OUT."""
        if command == "feature_extractor":
            return [command, "--database_path", database, "--image_path",
                    Scene.images, *CPU]
        if command.endswith("_matcher"):
            return [command, "--database_path", database, *CPU_MATCHING]
        if command == "point_triangulator":
            return [command, "--database_path", database, "--image_path",
                    Scene.images, "--input_path", Scene.model,
                    "--output_path", out]
        return [command, "--database_path", database, "--image_path",
                Scene.images, "--output_path", out]


# ---------------------------------------------------------------------------
# Databases


def sql_damage(*statements):
    """A damage made by SQL statements on a copy of the matched database."""
    def make(path):
        shutil.copy(Scene.database, path)
        connection = sqlite3.connect(path)
        for statement in statements:
            connection.execute(statement)
        connection.commit()
        connection.close()
    return make


def byte_damage(change):
    """A damage made by change(bytes) of the matched database's file."""
    def make(path):
        with open(Scene.database, "rb") as f:
            data = f.read()
        with open(path, "wb") as f:
            f.write(change(data))
    return make


def swapped_pages(first, second):
    """A damage that swaps two pages of the matched database's file: the
    first page of table FIRST's b-tree (its root) and the first overflow
    page of table SECOND's rows (SQLite's dbstat table names them)."""
    def make(path):
        connection = sqlite3.connect(f"file:{Scene.database}?mode=ro",
                                     uri=True)
        try:
            page_size = connection.execute("PRAGMA page_size").fetchone()[0]
            a = connection.execute(
                "SELECT MIN(pageno) FROM dbstat WHERE name = ?",
                (first,)).fetchone()[0]
            b = connection.execute(
                "SELECT MIN(pageno) FROM dbstat WHERE name = ? AND "
                "pagetype = 'overflow'", (second,)).fetchone()[0]
        finally:
            connection.close()
        with open(Scene.database, "rb") as f:
            data = bytearray(f.read())
        # dbstat counts pages from 1.
        a, b = (a - 1) * page_size, (b - 1) * page_size
        data[a:a + page_size], data[b:b + page_size] = (
            data[b:b + page_size], data[a:a + page_size])
        with open(path, "wb") as f:
            f.write(data)
    return make


def random_bytes(n, seed):
    rng = random.Random(seed)
    return bytes(rng.getrandbits(8) for _ in range(n))


# (name, how to make it). Every one is refused by every command.
DAMAGED_DATABASES = [
    ("truncated to 10%", byte_damage(lambda d: d[:len(d) // 10])),
    ("truncated to 50%", byte_damage(lambda d: d[:len(d) // 2])),
    ("truncated to 90%", byte_damage(lambda d: d[:len(d) * 9 // 10])),
    ("random bytes", byte_damage(lambda d: random_bytes(8192, 1))),
    ("a text file", byte_damage(lambda d: b"not a database\n" * 200)),
    ("4 KiB zeroed in the middle", byte_damage(
        lambda d: d[:len(d) // 2] + bytes(4096) + d[len(d) // 2 + 4096:])),
    ("a page of images swapped with one of keypoints",
     swapped_pages("images", "keypoints")),
    ("a page of two_view_geometries swapped with one of descriptors",
     swapped_pages("two_view_geometries", "descriptors")),
    ("SQLite, not COLMAP", sql_damage(
        "DROP TABLE keypoints", "DROP TABLE descriptors", "DROP TABLE matches",
        "DROP TABLE two_view_geometries", "DROP TABLE frame_data",
        "DROP TABLE frames", "DROP TABLE images", "DROP TABLE rig_sensors",
        "DROP TABLE rigs", "DROP TABLE pose_priors", "DROP TABLE cameras",
        "CREATE TABLE notes (text TEXT)")),
    ("table images missing", sql_damage(
        "DROP TABLE frame_data", "DROP TABLE images")),
    ("table keypoints missing", sql_damage("DROP TABLE keypoints")),
    ("column cols of keypoints missing", sql_damage(
        "ALTER TABLE keypoints RENAME COLUMN cols TO columns")),
    ("format of COLMAP 99", sql_damage("PRAGMA user_version = 99000000")),
    ("keypoints blob short", sql_damage(
        "UPDATE keypoints SET data = substr(data, 1, 100) WHERE image_id = 1")),
    ("keypoints rows doubled", sql_damage(
        "UPDATE keypoints SET rows = 2 * rows WHERE image_id = 2")),
    ("keypoints of 3 columns", sql_damage(
        "UPDATE keypoints SET cols = 3 WHERE image_id = 1")),
    ("keypoints rows negative", sql_damage(
        "UPDATE keypoints SET rows = -5 WHERE image_id = 1")),
    ("keypoints blob NULL", sql_damage(
        "UPDATE keypoints SET data = NULL WHERE image_id = 3")),
    ("keypoints of a missing image", sql_damage(
        "UPDATE keypoints SET image_id = 77 WHERE image_id = 1")),
    ("descriptors blob short", sql_damage(
        "UPDATE descriptors SET data = substr(data, 1, 100) WHERE image_id = 1")),
    ("SIFT descriptors of 64 values", sql_damage(
        "UPDATE descriptors SET cols = 64, rows = 2 * rows WHERE image_id = 1")),
    ("one descriptor fewer than keypoints", sql_damage(
        "UPDATE descriptors SET rows = rows - 1, "
        "data = substr(data, 1, (rows - 1) * cols) WHERE image_id = 1")),
    ("matches blob short", sql_damage(
        "UPDATE matches SET data = substr(data, 1, 10)")),
    ("match of a keypoint out of range", sql_damage(
        "UPDATE matches SET data = x'ffffff7f00000000' || substr(data, 9)")),
    ("matches of 3 columns", sql_damage(
        "UPDATE matches SET cols = 3, rows = rows * 2 / 3 "
        "WHERE rows % 3 = 0")),
    ("matches of a missing image", sql_damage(
        "INSERT INTO matches SELECT 2147483647 * 1000 + 999, rows, cols, data "
        "FROM matches LIMIT 1")),
    ("verified matches blob short", sql_damage(
        "UPDATE two_view_geometries SET data = substr(data, 1, 10) "
        "WHERE rows > 0")),
    ("verified match out of range", sql_damage(
        "UPDATE two_view_geometries SET data = x'ffffff7f00000000' || "
        "substr(data, 9) WHERE rows > 0")),
    ("F of 2 bytes", sql_damage(
        "UPDATE two_view_geometries SET F = x'0000' WHERE rows > 0")),
    ("unknown two-view configuration", sql_damage(
        "UPDATE two_view_geometries SET config = 77")),
    ("unknown camera model", sql_damage("UPDATE cameras SET model = 999")),
    ("camera params blob short", sql_damage(
        "UPDATE cameras SET params = substr(params, 1, 16)")),
    ("camera param NaN", sql_damage(
        "UPDATE cameras SET params = x'000000000000f87f' || substr(params, 9)")),
    ("camera width 0", sql_damage("UPDATE cameras SET width = 0")),
    # The first keypoint of image 1 (x, y, a11, a12, a21, a22 as float32).
    ("keypoint x NaN", sql_damage(
        "UPDATE keypoints SET data = x'0000c07f' || substr(data, 5) "
        "WHERE image_id = 1")),
    ("keypoint shape infinite", sql_damage(
        "UPDATE keypoints SET data = substr(data, 1, 8) || x'0000807f' || "
        "substr(data, 13) WHERE image_id = 1")),
    ("keypoint far outside the image", sql_damage(
        "UPDATE keypoints SET data = x'00247449' || substr(data, 5) "
        "WHERE image_id = 1")),
    # A second row of image 1 without keypoints, in a table whose UNIQUE
    # constraint was lost.
    ("two images of one name", sql_damage(
        "CREATE TABLE images_copy AS SELECT * FROM images",
        "DROP TABLE images", "ALTER TABLE images_copy RENAME TO images",
        "INSERT INTO images SELECT 99, name, camera_id FROM images "
        "WHERE image_id = 1")),
    # EQUIRECTANGULAR w,h = 640,320 for a camera of 320x240 images.
    ("equirectangular w,h other than the image size", sql_damage(
        "UPDATE cameras SET model = 17, "
        "params = x'00000000000084400000000000007440'")),
    # UNIFIED_OMNI whose k2 is 1e300: each value allowed, no projection
    # that can be inverted over the 320x240 image.
    ("UNIFIED_OMNI k2 = 1e300", sql_damage(
        "UPDATE cameras SET model = 64, params = x'" + struct.pack(
            "<9d", 200, 200, 160, 120, 1, 0, 1e300, 0, 0).hex() + "'")),
    ("image of a missing camera", sql_damage(
        "UPDATE images SET camera_id = 77 WHERE image_id = 2")),
    ("frame of a missing image", sql_damage(
        "UPDATE frame_data SET data_id = 99 WHERE data_id = 2")),
    ("rig of a missing camera", sql_damage("UPDATE rigs SET ref_sensor_id = 55")),
    ("frame of a missing rig", sql_damage("UPDATE frames SET rig_id = 9")),
]
DATABASE_COMMANDS = ("exhaustive_matcher", "sequential_matcher", "mapper",
                     "point_triangulator", "feature_extractor", "global_mapper")


class BadDatabaseTest(BadInputCase):
    def refused(self, command, database, tag, case):
        """Runs COMMAND on DATABASE: a named error, nothing written to its
        output folder. Returns 1 (a run)."""
        out = self.path(f"out_{tag}_{command}")
        os.makedirs(out)
        code, output = run_bounded(self.command_args(command, database, out))
        self.assert_named_error(code, output, [database], case)
        self.assertEqual(os.listdir(out), [], "output written")
        return 1

    def test_damaged_databases_are_named_errors(self):
        runs = 0
        for index, (case, make) in enumerate(DAMAGED_DATABASES):
            database = self.path(f"db{index}.db")
            make(database)
            before = database_state(database)
            for command in DATABASE_COMMANDS:
                with self.subTest(case=case, command=command):
                    runs += self.refused(command, database, f"{index}", case)
                    self.assertEqual(database_state(database), before,
                                     f"{case}: the database changed")
        self.assertEqual(runs, len(DAMAGED_DATABASES) * len(DATABASE_COMMANDS))
        print(f"{runs} runs on {len(DAMAGED_DATABASES)} damaged databases, "
              "all named errors")

    def test_missing_and_empty_databases_are_named_errors(self):
        runs = 0
        for case in ("missing", "empty"):
            database = self.path(f"{case}.db")
            if case == "empty":
                open(database, "wb").close()
            for command in DATABASE_COMMANDS[:4]:
                with self.subTest(case=case, command=command):
                    runs += self.refused(command, database, case, case)
                    self.assertEqual(os.path.exists(database), case == "empty",
                                     "a database was created")
                    if case == "empty":
                        self.assertEqual(os.path.getsize(database), 0)
            # The database named by a project file (--project_path).
            project = self.path(f"{case}.ini")
            with open(project, "w") as f:
                f.write(f"database_path={database}\n"
                        f"image_path={Scene.images}\n")
            for command in ("exhaustive_matcher", "mapper"):
                with self.subTest(case=case, command=command, project=True):
                    out = self.path(f"out_{case}_project_{command}")
                    os.makedirs(out)
                    args = [command, "--project_path", project]
                    if command == "mapper":
                        args += ["--image_path", Scene.images,
                                 "--output_path", out]
                    code, output = run_bounded(args)
                    self.assert_named_error(code, output, [database, case],
                                            case)
                    self.assertEqual(os.listdir(out), [], "output written")
                    self.assertEqual(os.path.exists(database),
                                     case == "empty", "a database was created")
                    runs += 1
        self.assertEqual(runs, 12)

    def test_database_without_images_is_a_named_error(self):
        database = self.path("no_images.db")
        sql_damage("DELETE FROM two_view_geometries", "DELETE FROM matches",
                   "DELETE FROM keypoints", "DELETE FROM descriptors",
                   "DELETE FROM frame_data", "DELETE FROM frames",
                   "DELETE FROM images", "DELETE FROM rig_sensors",
                   "DELETE FROM rigs", "DELETE FROM cameras")(database)
        for command in ("exhaustive_matcher", "sequential_matcher"):
            with self.subTest(command=command):
                code, output = run_bounded(
                    self.command_args(command, database, None))
                self.assert_named_error(code, output, [database, "no images"],
                                        command)
        os.makedirs(self.path("out"))
        code, output = run_bounded(
            self.command_args("mapper", database, self.path("out")))
        self.assert_named_error(code, output, ["0 of 0 images"], "mapper")

    def test_locked_database_is_a_named_error_without_a_hang(self):
        database = self.path("locked.db")
        shutil.copy(Scene.database, database)
        before = database_state(database)
        holder = sqlite3.connect(database, isolation_level=None, timeout=0)
        holder.execute("BEGIN EXCLUSIVE")
        try:
            for command in ("exhaustive_matcher", "mapper"):
                os.makedirs(self.path("out_" + command))
                with self.subTest(command=command):
                    code, output = run_bounded(self.command_args(
                        command, database, self.path("out_" + command)))
                    self.assert_named_error(code, output,
                                            [database, "locked"], command)
        finally:
            holder.execute("ROLLBACK")
            holder.close()
        self.assertEqual(database_state(database), before)

    def test_older_layouts_still_work(self):
        # Not damage: a database matched without verification, and one of
        # a schema without the two-view table, are matched again.
        for case, make in (
                ("no verified pairs", sql_damage(
                    "DELETE FROM two_view_geometries")),
                ("no two-view table", sql_damage(
                    "DROP TABLE two_view_geometries"))):
            database = self.path(case.replace(" ", "_") + ".db")
            make(database)
            with self.subTest(case=case):
                code, output = run_bounded(
                    self.command_args("exhaustive_matcher", database, None))
                self.assertEqual(code, 0, output[-2000:])
                connection = sqlite3.connect(database)
                verified = connection.execute(
                    "SELECT count(*) FROM two_view_geometries WHERE rows > 0"
                ).fetchone()[0]
                connection.close()
                self.assertGreater(verified, 0)


# ---------------------------------------------------------------------------
# Images


def jpeg_bytes():
    with open(os.path.join(Scene.images, "cam000.jpg"), "rb") as f:
        return f.read()


def bad_images():
    """[(case, file name, bytes or None for a dangling link)]."""
    jpeg = jpeg_bytes()
    third = len(jpeg) // 3
    pgm_header = b"P5\n320 240\n255\n"
    with open(os.path.join(Scene.root, "png", "images", "cam000.png"),
              "rb") as f:
        png = f.read()
    return [
        ("JPEG cut at half", "bad.jpg", jpeg[:len(jpeg) // 2]),
        ("JPEG cut before its last 10 bytes", "bad.jpg", jpeg[:-10]),
        ("JPEG cut in its header", "bad.jpg", jpeg[:100]),
        ("JPEG with 2000 random bytes", "bad.jpg",
         jpeg[:third] + random_bytes(2000, 7) + jpeg[third + 2000:]),
        ("PNG cut at half", "bad.png", png[:len(png) // 2]),
        ("empty file", "bad.jpg", b""),
        ("text named .jpg", "bad.jpg", b"this is not an image\n"),
        ("PGM of half its pixels", "bad.pgm",
         pgm_header + bytes(320 * 120)),
        ("PGM declaring 10^10 pixels", "bad.pgm",
         b"P5\n100000 100000\n255\n" + bytes(1000)),
        ("1x1 image", "bad.pgm", b"P5\n1 1\n255\n\x80"),
        ("8x8 image", "bad.pgm", b"P5\n8 8\n255\n" + bytes(range(64))),
        ("dangling link", "bad.jpg", None),
    ]


class BadImageTest(BadInputCase):
    def test_bad_images_are_named_and_the_others_extracted(self):
        png_scene = os.path.join(Scene.root, "png")
        if not os.path.exists(png_scene):
            subprocess.run([RENDER, "--output", png_scene, "--layout", "ring",
                            "--num_cameras", "2", "--width", "160",
                            "--height", "120", "--supersample", "1",
                            "--format", "png"], check=True, capture_output=True)
        cases = bad_images()
        for index, (case, name, data) in enumerate(cases):
            folder = self.path(f"images{index}")
            os.makedirs(folder)
            for good in ("cam001.jpg", "cam002.jpg"):
                shutil.copy(os.path.join(Scene.images, good), folder)
            if data is None:
                os.symlink(self.path("nowhere.jpg"), os.path.join(folder, name))
            else:
                with open(os.path.join(folder, name), "wb") as f:
                    f.write(data)
            database = self.path(f"db{index}.db")
            with self.subTest(case=case):
                code, output = run_bounded(
                    ["feature_extractor", "--database_path", database,
                     "--image_path", folder, *CPU])
                self.assert_named_error(code, output, [name], case)
                connection = sqlite3.connect(database)
                extracted = dict(connection.execute(
                    "SELECT name, rows FROM images JOIN keypoints "
                    "USING (image_id)").fetchall())
                connection.close()
                self.assertNotIn(name, extracted, f"{case}: extracted")
                self.assertEqual(sorted(extracted), ["cam001.jpg", "cam002.jpg"])
                self.assertTrue(all(rows > 100 for rows in extracted.values()))
        self.assertEqual(len(cases), 12)


# ---------------------------------------------------------------------------
# Option values and paths


# (command, option, value): the message names the option.
BAD_OPTIONS = [
    ("feature_extractor", "--SiftExtraction.max_num_features", "-1"),
    ("feature_extractor", "--SiftExtraction.max_num_features", "0"),
    ("feature_extractor", "--SiftExtraction.peak_threshold", "nan"),
    ("feature_extractor", "--SiftExtraction.peak_threshold", "-1"),
    ("feature_extractor", "--SiftExtraction.edge_threshold", "inf"),
    ("feature_extractor", "--SiftExtraction.octave_resolution", "0"),
    ("feature_extractor", "--FeatureExtraction.max_image_size", "abc"),
    ("feature_extractor", "--ImageReader.camera_params", "nan,1,2,3"),
    ("feature_extractor", "--ImageReader.camera_model", "NO_SUCH_MODEL"),
    ("exhaustive_matcher", "--SiftMatching.max_ratio", "nan"),
    ("exhaustive_matcher", "--SiftMatching.max_ratio", "0"),
    ("exhaustive_matcher", "--SiftMatching.max_distance", "-1"),
    ("exhaustive_matcher", "--TwoViewGeometry.max_error", "-1"),
    ("exhaustive_matcher", "--TwoViewGeometry.max_error", "nan"),
    ("exhaustive_matcher", "--TwoViewGeometry.confidence", "2"),
    ("exhaustive_matcher", "--TwoViewGeometry.min_num_inliers", "-1"),
    ("exhaustive_matcher", "--TwoViewGeometry.min_inlier_ratio", "nan"),
    ("mapper", "--Mapper.init_min_num_inliers", "-5"),
    ("mapper", "--Mapper.abs_pose_max_error", "nan"),
    ("mapper", "--Mapper.abs_pose_max_error", "-1"),
    ("mapper", "--Mapper.min_model_size", "-1"),
    ("mapper", "--Mapper.filter_max_reproj_error", "nan"),
    ("mapper", "--Mapper.init_max_error", "inf"),
    ("mapper", "--Mapper.tri_min_angle", "-1"),
    ("mapper", "--Mapper.tri_min_angle", "nan"),
    ("mapper", "--Mapper.max_num_models", "0"),
    ("mapper", "--Mapper.camera_only_ba_tau_px", "nan"),
    ("mapper", "--Mapper.camera_only_ba_tau_px", "-2"),
    ("mapper", "--Mapper.ba_sphere_residual", "geodesic"),
    ("mapper", "--Mapper.min_num_matches", "abc"),
]


class BadOptionTest(BadInputCase):
    def test_bad_option_values_are_named_errors(self):
        for index, (command, option, value) in enumerate(BAD_OPTIONS):
            database = self.path(f"db{index}.db")
            shutil.copy(Scene.database if command != "feature_extractor"
                        else Scene.extracted, database)
            before = database_state(database)
            out = self.path(f"out{index}")
            os.makedirs(out)
            case = f"{command} {option} {value}"
            with self.subTest(case=case):
                code, output = run_bounded(
                    self.command_args(command, database, out) + [option, value])
                self.assert_named_error(code, output, [option.lstrip("-")],
                                        case, internal_checks=True)
                self.assertEqual(database_state(database), before, case)
                self.assertEqual(os.listdir(out), [], case)
        self.assertEqual(len(BAD_OPTIONS), 30)

    def test_cameras_without_a_usable_projection_are_not_extracted(self):
        """A camera given on the command line whose values are each allowed
        but leave no projection over the images (UNIFIED_OMNI with k2 =
        1e300, a principal point a thousand images away) is named before
        any image is extracted; the database holds no image."""
        cases = [
            ("UNIFIED_OMNI", "200,200,160,120,1,0,1e300,0,0", "UNIFIED_OMNI"),
            ("PINHOLE", "250,250,320000,120", "principal point"),
        ]
        for index, (model, params, name) in enumerate(cases):
            database = self.path(f"camera{index}.db")
            with self.subTest(model=model):
                code, output = run_bounded(
                    ["feature_extractor", "--database_path", database,
                     "--image_path", Scene.images, "--ImageReader.camera_model",
                     model, "--ImageReader.camera_params", params,
                     "--ImageReader.single_camera", "1", *CPU])
                self.assert_named_error(code, output, [name], model,
                                        internal_checks=True)
                if os.path.exists(database):
                    connection = sqlite3.connect(database)
                    try:
                        self.assertEqual(connection.execute(
                            "SELECT count(*) FROM images").fetchone()[0], 0)
                    finally:
                        connection.close()

    def test_sphera_option_ranges_are_named_errors(self):
        """Values outside the documented range of SPHERA's own commands'
        options are named before any work: nothing is written and the
        database is unchanged."""
        database = self.path("sphera_options.db")
        shutil.copy(Scene.database, database)
        before = database_state(database)
        calibration = self.path("calibration.yaml")
        with open(calibration, "w") as f:
            f.write("cam0:\n  camera_model: pinhole\n")
        # (command and its arguments, option and value, names in the error);
        # OUT is the output folder, which must stay empty.
        cases = [
            (["sphere_bundle_adjuster", "--input_path", Scene.model,
              "--output_path", "OUT"], ["--loss_scale_px", "-1"],
             ["--loss_scale_px"]),
            (["sphere_bundle_adjuster", "--input_path", Scene.model,
              "--output_path", "OUT"], ["--tau_px", "0"], ["--tau_px"]),
            (["rig_check", "--database_path", database],
             ["--min_num_inliers", "1000000"], ["--min_num_inliers"]),
            (["rig_check", "--database_path", database],
             ["--max_angle_deg", "270"], ["--max_angle_deg"]),
            (["rig_preset", "--camera", "dual_fisheye", "--output_path",
              "OUT/rig_config.json"],
             ["--image_width", "2000000", "--image_height", "1000000"],
             ["--image_width"]),
            (["calibration_importer", "--input_path", calibration,
              "--output_path", "OUT"], ["--format", "matlab"],
             ["--format", "matlab"]),
            (["dual_fisheye_splitter", "--input_path", Scene.images,
              "--output_path", "OUT"], ["--circles", "80,60,50;240,60,0"],
             ["--circles", "radius of lens 1"]),
            (["dual_fisheye_splitter", "--input_path", Scene.images,
              "--output_path", "OUT"], ["--black_level", "300"],
             ["--black_level"]),
        ]
        for index, (args, values, names) in enumerate(cases):
            out = self.path(f"sphera_out{index}")
            os.makedirs(out)
            args = [out if a == "OUT" else a.replace("OUT/", out + "/")
                    for a in args]
            case = " ".join([args[0]] + values)
            with self.subTest(case=case):
                code, output = run_bounded(args + values)
                self.assert_named_error(code, output, names, case)
                self.assertEqual(os.listdir(out), [], case)
        self.assertEqual(database_state(database), before)

    def test_sphere_bundle_adjuster_enums_in_any_letter_case(self):
        """Its --mode, --residual and --loss take the enum names in any
        letter case, as COLMAP's own enum options; another word is named."""
        for index, values in enumerate((
                ["--mode", "CAMERA_ONLY"],
                ["--mode", "full", "--residual", "Pixel", "--loss", "cauchy"])):
            out = self.path(f"ba{index}")
            os.makedirs(out)
            code, output = run_bounded(
                ["sphere_bundle_adjuster", "--input_path", Scene.model,
                 "--output_path", out] + values)
            self.assertEqual(code, 0, output[-2500:])
            self.assertIn("images.bin", os.listdir(out))
        for option in ("--mode", "--residual", "--loss"):
            out = self.path(f"ba_bad{option}")
            os.makedirs(out)
            code, output = run_bounded(
                ["sphere_bundle_adjuster", "--input_path", Scene.model,
                 "--output_path", out, option, "nonsense"])
            self.assert_named_error(code, output, [option, "nonsense"],
                                    option, internal_checks=True)
            self.assertEqual(os.listdir(out), [], option)

    def test_bad_paths_are_named_errors(self):
        missing = self.path("does_not_exist")
        database = self.path("db.db")
        shutil.copy(Scene.database, database)
        os.makedirs(self.path("out"))
        cases = [
            ("image folder missing", ["feature_extractor", "--database_path",
                                      self.path("new.db"), "--image_path",
                                      missing, *CPU], missing),
            ("image list missing", ["feature_extractor", "--database_path",
                                    self.path("new2.db"), "--image_path",
                                    Scene.images, "--image_list_path",
                                    missing, *CPU], missing),
            ("mask folder missing", ["feature_extractor", "--database_path",
                                     self.path("new3.db"), "--image_path",
                                     Scene.images, "--ImageReader.mask_path",
                                     missing, *CPU], missing),
            ("database folder missing", ["feature_extractor", "--database_path",
                                         os.path.join(missing, "db.db"),
                                         "--image_path", Scene.images, *CPU],
             missing),
            ("mapper output folder missing", ["mapper", "--database_path",
                                              database, "--image_path",
                                              Scene.images, "--output_path",
                                              missing], missing),
            ("triangulator input model missing", [
                "point_triangulator", "--database_path", database,
                "--image_path", Scene.images, "--input_path", missing,
                "--output_path", self.path("out")], missing),
            ("converter input model missing", [
                "model_converter", "--input_path", missing, "--output_path",
                self.path("out"), "--output_type", "TXT"], missing),
            ("converter output folder missing", [
                "model_converter", "--input_path", Scene.model,
                "--output_path", missing, "--output_type", "TXT"], missing),
        ]
        before = database_state(database)
        for case, args, name in cases:
            with self.subTest(case=case):
                code, output = run_bounded(args)
                self.assert_named_error(code, output, [name], case,
                                        internal_checks=True)
                self.assertFalse(os.path.exists(missing), case)
        self.assertEqual(database_state(database), before)
        self.assertEqual(os.listdir(self.path("out")), [])


    def test_undistorters_without_views_are_named_errors(self):
        """An undistorter that would write a workspace without its views
        (no registered image, an image list naming none of the model's
        images, image files missing) names why, exits 1 and writes
        nothing."""
        empty_model = self.path("empty_model")
        os.makedirs(empty_model)
        with open(os.path.join(empty_model, "cameras.txt"), "w") as f:
            f.write("1 PINHOLE 320 240 250 250 160 120\n")
        for name in ("images.txt", "points3D.txt"):
            open(os.path.join(empty_model, name), "w").close()
        image_list = self.path("list.txt")
        with open(image_list, "w") as f:
            f.write("not_in_the_model.jpg\n")
        no_images = self.path("no_images")
        os.makedirs(no_images)
        cases = [
            ("image_undistorter, model without images", "image_undistorter",
             empty_model, Scene.images, [], [empty_model, "no registered"]),
            ("image_undistorter, list naming no image", "image_undistorter",
             Scene.model, Scene.images, ["--image_list_path", image_list],
             [image_list]),
            ("image_undistorter, image files missing", "image_undistorter",
             Scene.model, no_images, [], [".jpg not found in " + no_images]),
            ("sphere_undistorter, model without images", "sphere_undistorter",
             empty_model, Scene.images, [], ["no registered image"]),
            ("sphere_undistorter, image files missing", "sphere_undistorter",
             Scene.model, no_images, [], [".jpg not found in " + no_images]),
        ]
        for index, (case, command, model, images, extra, names) in enumerate(
                cases):
            out = self.path(f"out{index}")
            os.makedirs(out)
            with self.subTest(case=case):
                code, output = run_bounded(
                    [command, "--input_path", model, "--image_path", images,
                     "--output_path", out, *extra])
                self.assert_named_error(code, output, names, case)
                self.assertEqual(os.listdir(out), [], case)
        # The model's camera replaced by one whose values are each allowed
        # but leave no usable projection over the 320x240 image.
        text_model = self.path("text_model")
        os.makedirs(text_model)
        run_colmap("model_converter", "--input_path", Scene.model,
                   "--output_path", text_model, "--output_type", "TXT")
        edge_cameras = [
            ("PINHOLE principal point far outside",
             "PINHOLE 320 240 250 250 1000000 120", "PINHOLE principal point"),
            ("UNIFIED_OMNI k2 = 1e300",
             "UNIFIED_OMNI 320 240 200 200 160 120 1 0 1e300 0 0",
             "UNIFIED_OMNI"),
        ]
        for index, (case, camera, name) in enumerate(edge_cameras):
            model = self.path(f"edge_model{index}")
            shutil.copytree(text_model, model)
            with open(os.path.join(model, "cameras.txt")) as f:
                lines = f.read().splitlines()
            with open(os.path.join(model, "cameras.txt"), "w") as f:
                for text in lines:
                    if text and not text.startswith("#"):
                        text = text.split()[0] + " " + camera
                    f.write(text + "\n")
            for command in ("image_undistorter", "sphere_undistorter"):
                out = self.path(f"edge_out{index}_{command}")
                os.makedirs(out)
                with self.subTest(case=case, command=command):
                    code, output = run_bounded(
                        [command, "--input_path", model, "--image_path",
                         Scene.images, "--output_path", out])
                    self.assert_named_error(code, output, ["camera 1", name],
                                            case)
                    self.assertEqual(os.listdir(out), [], case)
        # The same commands on the intact model write their workspaces.
        for command in ("image_undistorter", "sphere_undistorter"):
            out = self.path("valid_" + command)
            os.makedirs(out)
            code, output = run_bounded([command, "--input_path", Scene.model,
                                        "--image_path", Scene.images,
                                        "--output_path", out])
            self.assertEqual(code, 0, output[-2000:])
            self.assertIn("images", os.listdir(out))


# ---------------------------------------------------------------------------
# Matching that verifies no pair


# An EUCM camera whose beta shrinks its image circle to a few pixels: a
# valid camera of the wrong lens, under which no pair can be verified.
BROKEN_EUCM = ["--ImageReader.camera_model", "EUCM", "--ImageReader.camera_params",
               "20,20,160,120,1,100", "--ImageReader.single_camera", "1"]
TIGHT = ["--TwoViewGeometry.max_error", "1e-6"]  # no RANSAC fit has inliers


def verified_pairs(database):
    """(pairs with raw matches, pairs with a verified two-view geometry)."""
    connection = sqlite3.connect(f"file:{database}?mode=ro", uri=True)
    try:
        return tuple(connection.execute(query).fetchone()[0] for query in (
            "SELECT count(*) FROM matches WHERE rows > 0",
            "SELECT count(*) FROM two_view_geometries WHERE rows > 0 AND "
            "config >= 2"))
    finally:
        connection.close()


class UnverifiedMatchingTest(BadInputCase):
    """A matching run after which the database holds no verified pair (a
    wrong camera, nothing in common, a pairing that selects nothing) says
    why and exits 1; the matches it found stay in the database."""

    def test_matching_that_verifies_nothing_is_a_named_error(self):
        broken = self.path("broken.db")
        run_colmap("feature_extractor", "--database_path", broken,
                   "--image_path", Scene.images, *BROKEN_EUCM, *CPU)
        one = self.path("one")
        os.makedirs(one)
        shutil.copy(os.path.join(Scene.images, sorted(os.listdir(
            Scene.images))[0]), one)
        single = self.path("single.db")
        run_colmap("feature_extractor", "--database_path", single,
                   "--image_path", one, *CPU)
        pair_list = self.path("pairs.txt")
        names = sorted(os.listdir(Scene.images))
        with open(pair_list, "w") as f:
            for a, b in zip(names, names[1:]):
                f.write(f"{a} {b}\n")
        all_pairs = NUM_IMAGES * (NUM_IMAGES - 1) // 2
        # (case, source database, arguments, names in the error, pairs with
        # raw matches afterwards)
        cases = [
            ("exhaustive, broken camera", broken,
             ["exhaustive_matcher", *CPU_MATCHING],
             ["camera 1 (EUCM) lifts only", "yet no two-view geometry fits"],
             None),
            ("sequential, no fit", Scene.extracted,
             ["sequential_matcher", *CPU_MATCHING, *TIGHT],
             ["yet no two-view geometry fits"], None),
            ("imported pairs, no fit", Scene.extracted,
             ["matches_importer", "--match_list_path", pair_list,
              "--match_type", "pairs", *CPU_MATCHING, *TIGHT],
             ["yet no two-view geometry fits"], None),
            ("exhaustive, too few matches", Scene.extracted,
             ["exhaustive_matcher", *CPU_MATCHING,
              "--TwoViewGeometry.min_num_inliers", "100000"],
             ["none has the 100000 raw matches"], 0),
            ("spatial, no position priors", Scene.extracted,
             ["spatial_matcher", *CPU_MATCHING],
             ["selected none of the 16 images' pairs", "here 0"], 0),
            ("exhaustive, one image", single,
             ["exhaustive_matcher", *CPU_MATCHING],
             ["holds 1 image(s)"], 0),
        ]
        for index, (case, source, args, reasons, raw) in enumerate(cases):
            database = self.path(f"match{index}.db")
            shutil.copy(source, database)
            with self.subTest(case=case):
                code, output = run_bounded(
                    [args[0], "--database_path", database, *args[1:]])
                self.assert_named_error(
                    code, output, [database, *reasons], case)
                if "camera 1" not in reasons[0]:
                    self.assertNotIn("lifts only", output, case)
                matched, verified = verified_pairs(database)
                self.assertEqual(verified, 0, case)
                if raw is None:  # the matches found are kept
                    self.assertGreater(matched, 0, case)
                else:
                    self.assertEqual(matched, raw, case)
                if index == 0:  # the counts it gives are the database's
                    self.assertRegex(output, f"of {all_pairs} pairs matched, "
                                     f"{matched} ha(s|ve) at least 15 raw "
                                     "matches")
        # geometric_verifier on the broken camera's kept matches: the same
        # error; with the camera right, the same matches verify (exit 0).
        for case, params in (("broken camera", None),
                             ("camera corrected", "160,160,160,120,0,1")):
            database = self.path(case.replace(" ", "_") + ".db")
            shutil.copy(self.path("match0.db"), database)
            connection = sqlite3.connect(database)
            connection.execute("DELETE FROM two_view_geometries")
            if params:
                connection.execute(
                    "UPDATE cameras SET params = ?", (struct.pack(
                        "6d", *map(float, params.split(","))),))
            connection.commit()
            connection.close()
            with self.subTest(case="geometric_verifier, " + case):
                code, output = run_bounded(
                    ["geometric_verifier", "--database_path", database])
                if params:
                    self.assertEqual(code, 0, output[-2000:])
                    self.assertGreater(verified_pairs(database)[1], 0)
                else:
                    self.assert_named_error(
                        code, output, [database, "camera 1 (EUCM) lifts only"],
                        case)
        # Valid matching still succeeds: the scene's database was matched
        # with check=True in setUpModule, and holds verified pairs.
        self.assertGreater(verified_pairs(Scene.database)[1], 0)


# ---------------------------------------------------------------------------
# Killed runs


class KilledRunTest(BadInputCase):
    def kill_after(self, args, seconds):
        """Starts `colmap ARGS` and kills it (SIGKILL) after SECONDS, or
        lets it finish first; returns whether it was killed."""
        process = subprocess.Popen([COLMAP, *args], stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        try:
            process.wait(timeout=seconds)
            return False
        except subprocess.TimeoutExpired:
            process.send_signal(signal.SIGKILL)
            process.wait()
            return True

    def check_complete(self, database):
        """Every image once, with keypoints and descriptors (the run that
        made it complete opened the killed run's database, which passed
        COLMAP's check of it), and no camera that no image uses (a killed
        extraction leaves the cameras it had written for images it had
        not; the next run removes them)."""
        connection = sqlite3.connect(database)
        try:
            images = connection.execute("SELECT count(*) FROM images").fetchone()[0]
            extracted = connection.execute(
                "SELECT count(*) FROM images JOIN keypoints USING (image_id) "
                "JOIN descriptors USING (image_id)").fetchone()[0]
            orphans = connection.execute(
                "SELECT count(*) FROM cameras WHERE camera_id NOT IN "
                "(SELECT camera_id FROM images)").fetchone()[0]
        finally:
            connection.close()
        self.assertEqual(images, NUM_IMAGES)
        self.assertEqual(extracted, NUM_IMAGES)
        self.assertEqual(orphans, 0, "cameras that no image uses")

    def test_killed_extraction_and_matching_resume(self):
        killed = 0
        for index, delay in enumerate((0.3, 0.8, 1.5, 3.0)):
            database = self.path(f"kill{index}.db")
            extract = ["feature_extractor", "--database_path", database,
                       "--image_path", Scene.images,
                       "--ImageReader.camera_model", "PINHOLE", *CPU]
            with self.subTest(step="extraction", delay=delay):
                killed += self.kill_after(extract, delay)
                code, output = run_bounded(extract)
                self.assertEqual(code, 0, output[-2000:])
                self.check_complete(database)
            match = ["exhaustive_matcher", "--database_path", database,
                     *CPU_MATCHING]
            with self.subTest(step="matching", delay=delay):
                killed += self.kill_after(match, delay)
                code, output = run_bounded(match)
                self.assertEqual(code, 0, output[-2000:])
                connection = sqlite3.connect(database)
                pairs = connection.execute(
                    "SELECT count(*) FROM two_view_geometries").fetchone()[0]
                connection.close()
                self.assertEqual(pairs, NUM_IMAGES * (NUM_IMAGES - 1) // 2)
        # At least the early kills hit running commands.
        self.assertGreaterEqual(killed, 4)

    def test_killed_model_writes_leave_the_earlier_model(self):
        # A model large enough that writing it takes a while: the mapper's
        # model with its points repeated; model_converter writes it over an
        # earlier model and is killed at moments spread over its run.
        text = self.path("big_text")
        os.makedirs(text)
        run_colmap("model_converter", "--input_path", Scene.model,
                   "--output_path", text, "--output_type", "TXT")
        with open(os.path.join(text, "points3D.txt")) as f:
            lines = [line for line in f if line.strip() and line[0] != "#"]
        with open(os.path.join(text, "points3D.txt"), "w") as f:
            next_id = 1
            for copy in range(40):
                for line in lines:
                    fields = line.split()
                    # Copies without tracks: the images keep referring to
                    # the first copy's points.
                    if copy:
                        fields = [str(10 ** 7 + next_id)] + fields[1:8]
                    f.write(" ".join(fields) + "\n")
                    next_id += 1
        output = self.path("model")
        os.makedirs(output)
        run_colmap("model_converter", "--input_path", Scene.model,
                   "--output_path", output, "--output_type", "TXT")
        convert = ["model_converter", "--input_path", text, "--output_path",
                   output, "--output_type", "TXT"]
        start = time.monotonic()
        code, log = run_bounded(convert)
        self.assertEqual(code, 0, log[-2000:])
        duration = time.monotonic() - start
        killed = 0
        # Reading the text model takes most of the run, writing the rest.
        for fraction in [0.55 + 0.03 * k for k in range(15)]:
            with self.subTest(fraction=fraction):
                killed += self.kill_after(convert, duration * fraction)
                code, log = run_bounded(["model_analyzer", "--path", output])
                self.assertEqual(code, 0, log[-2000:])
                self.assertEqual(
                    sorted(n for n in os.listdir(output)
                           if not n.endswith(".tmp")),
                    sorted(os.listdir(text)))
        self.assertGreaterEqual(killed, 4)


if __name__ == "__main__":
    unittest.main()
