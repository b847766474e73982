"""`colmap rig_check` on the rendered 8-lens ring (195° EUCM lenses 45°
apart on a 6 cm ring): after matching, the rig config the renderer wrote
agrees with the verified pairs inside each frame (every lens with a
measured pair within a few degrees, exit 0); the same database configured
from that config with one lens turned 90° about its vertical is refused
before mapping (exit 1) naming that lens and an angle near 90°, and the
database is left as it was."""
import copy
import hashlib
import json
import math
import os
import re
import shutil
import sqlite3

from cli_util import TempDirTestCase, main_with_render
from sphera_common import (axis_angle_quat, extract_features,
                           match_exhaustive, quat_mul, run_colmap, run_render)

FRAMES = 2
LENSES = 8
WRONG_LENS = 3
# "  rig 1 camera 4 (lens3/): 1.23 deg off, 2 lens pair(s), ..."
LENS_LINE = re.compile(r"^  rig \d+ camera (\d+) \((\S*)\)(?: ref)?: "
                       r"([0-9.]+) deg off", re.MULTILINE)


def file_digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


class RigCheckTest(TempDirTestCase):
    def lens_angles(self, output):
        """{image prefix: degrees off} of rig_check's lens lines."""
        return {prefix: float(angle)
                for _, prefix, angle in LENS_LINE.findall(output)}

    def test_correct_config_passes_and_a_turned_lens_is_named(self):
        scene = self.path("scene")
        # Small lenses, one sample per pixel, two frames: neighbouring lenses
        # of a frame overlap by 150°, enough for a few hundred matches.
        run_render(scene, "--rig_preset", "ring8", "--frames", FRAMES,
                   "--lens_size", 320, "--supersample", 1, "--seed", 0)
        images = os.path.join(scene, "images")
        database = self.path("database.db")
        extract_features(database, images, "EUCM", "--ImageReader.mask_path",
                         os.path.join(scene, "masks"),
                         "--ImageReader.single_camera_per_folder", "1",
                         "--SiftExtraction.max_num_features", "1000",
                         single_camera=False)
        # Extracted, not yet configured: every lens its own rig.
        plain_database = self.path("plain.db")
        shutil.copy(database, plain_database)
        result = run_colmap("rig_check", "--database_path", plain_database,
                            check=False)
        self.assertEqual(result.returncode, 1, result.stdout)
        self.assertIn("no rig of more than one camera", result.stdout)

        config_path = os.path.join(scene, "rig_config.json")
        run_colmap("rig_configurator", "--database_path", database,
                   "--rig_config_path", config_path)
        match_exhaustive(database)
        wrong_database = self.path("wrong.db")
        shutil.copy(database, wrong_database)
        # Without verified pairs inside frames nothing is checked: said, and
        # not a failure.
        unmatched_database = self.path("unmatched.db")
        shutil.copy(database, unmatched_database)
        with sqlite3.connect(unmatched_database) as connection:
            connection.execute("DELETE FROM two_view_geometries")
        connection.close()
        result = run_colmap("rig_check", "--database_path",
                            unmatched_database)
        self.assertIn("every lens unchecked", result.stdout)
        self.assertEqual(result.stdout.count("unchecked (no lens pair"),
                         LENSES, result.stdout)

        result = run_colmap("rig_check", "--database_path", database)
        print(result.stdout)
        angles = self.lens_angles(result.stdout)
        self.assertEqual(len(angles), LENSES, result.stdout)
        print("correct config, deg off per lens:", angles)
        for prefix, angle in angles.items():
            self.assertLess(angle, 3, prefix)
        self.assertIn("agrees with the images", result.stdout)
        # Options checked before the database is read; a missing database.
        for angle in ("0", "181"):
            result = run_colmap("rig_check", "--database_path", database,
                                "--max_angle_deg", angle, check=False)
            self.assertEqual(result.returncode, 1, result.stdout)
            self.assertIn(f"--max_angle_deg must be in (0, 180], got {angle}",
                          result.stdout)
        result = run_colmap("rig_check", "--database_path",
                            self.path("none.db"), check=False)
        self.assertEqual(result.returncode, 1, result.stdout)
        self.assertIn("none.db", result.stdout)

        # The same database configured with lens 3 turned 90° about its y.
        with open(config_path) as f:
            config = json.load(f)
        wrong = copy.deepcopy(config)
        camera = wrong[0]["cameras"][WRONG_LENS]
        self.assertEqual(camera["image_prefix"], f"lens{WRONG_LENS}/")
        camera["cam_from_rig_rotation"] = list(quat_mul(
            axis_angle_quat((0, 1, 0), math.pi / 2),
            camera["cam_from_rig_rotation"]))
        wrong_config_path = self.path("wrong_rig_config.json")
        with open(wrong_config_path, "w") as f:
            json.dump(wrong, f)
        run_colmap("rig_configurator", "--database_path", wrong_database,
                   "--rig_config_path", wrong_config_path)
        before = file_digest(wrong_database)
        result = run_colmap("rig_check", "--database_path", wrong_database,
                            check=False)
        print(result.stdout)
        self.assertEqual(result.returncode, 1, result.stdout)
        self.assertEqual(file_digest(wrong_database), before)
        errors = re.findall(r"direction of rig \d+ camera \d+ \((\S*)\) is "
                            r"([0-9.]+) deg off", result.stdout)
        print("turned lens, named:", errors)
        self.assertEqual([prefix for prefix, _ in errors],
                         [f"lens{WRONG_LENS}/"], result.stdout)
        self.assertAlmostEqual(float(errors[0][1]), 90, delta=10)
        # The other lenses still agree.
        angles = self.lens_angles(result.stdout)
        for prefix, angle in angles.items():
            if prefix != f"lens{WRONG_LENS}/":
                self.assertLess(angle, 3, prefix)


if __name__ == "__main__":
    main_with_render()
