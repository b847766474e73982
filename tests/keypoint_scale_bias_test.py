"""scripts/keypoint_scale_bias.py on a hand-made model and database: the
keypoints of one scale sit exactly at the projection, those of another
0.1 px towards the principal point, and the table says so per radius and
scale; the projections of its lens models match the camera models."""
import os
import sqlite3
import subprocess
import sys
import unittest

import numpy as np

from cli_util import TempDirTestCase
from sphera_common import REPO_ROOT

sys.path.insert(0, os.path.join(REPO_ROOT, "scripts"))
import keypoint_scale_bias as bias  # noqa: E402

WIDTH, HEIGHT = 1000, 1000
KB = ["OPENCV_FISHEYE", WIDTH, HEIGHT,
      [300.0, 300.0, 500.0, 500.0, 0.02, -0.01, 0.003, -0.0005]]
SHIFT_PX = -0.1  # radial shift of the large keypoints (towards the centre)


def write_case(root, camera, num_points=400, seed=0):
    """A text model of one camera and one image at the origin, points all
    around the lens's field, and a database whose keypoints are the
    observations, with scale 1 px (exact) or 10 px (shifted radially)."""
    rng = np.random.default_rng(seed)
    model, width, height, params = camera
    directions = rng.normal(size=(num_points, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    directions = directions[directions[:, 2] > -0.1]  # within about 186°
    X = directions * rng.uniform(2, 6, size=(len(directions), 1))
    uv, (cx, cy) = bias.project(model, params, X)
    scales = np.where(np.arange(len(X)) % 2 == 0, 1.0, 10.0)
    rel = uv - [cx, cy]
    radius = np.linalg.norm(rel, axis=1, keepdims=True)
    uv = uv + np.where(scales[:, None] > 5, SHIFT_PX * rel / radius, 0)
    text = os.path.join(root, "model")
    os.makedirs(text)
    with open(os.path.join(text, "cameras.txt"), "w") as f:
        f.write(f"1 {model} {width} {height} "
                + " ".join(repr(p) for p in params) + "\n")
    with open(os.path.join(text, "images.txt"), "w") as f:
        f.write("1 1 0 0 0 0 0 0 1 lens/img.jpg\n")
        f.write(" ".join(f"{u!r} {v!r} {k + 1}"
                         for k, (u, v) in enumerate(uv)) + "\n")
    with open(os.path.join(text, "points3D.txt"), "w") as f:
        for k, p in enumerate(X):
            f.write(f"{k + 1} {p[0]!r} {p[1]!r} {p[2]!r} 0 0 0 0 1 {k}\n")
    database = os.path.join(root, "database.db")
    con = sqlite3.connect(database)
    con.execute("CREATE TABLE images (image_id INTEGER, name TEXT, "
                "camera_id INTEGER)")
    con.execute("CREATE TABLE keypoints (image_id INTEGER, rows INTEGER, "
                "cols INTEGER, data BLOB)")
    con.execute("INSERT INTO images VALUES (1, 'lens/img.jpg', 1)")
    keypoints = np.zeros((len(X), 6), dtype=np.float32)
    keypoints[:, :2] = uv
    keypoints[:, 2] = keypoints[:, 5] = scales
    con.execute("INSERT INTO keypoints VALUES (1, ?, 6, ?)",
                (len(X), keypoints.tobytes()))
    con.commit()
    con.close()
    return text, database


class KeypointScaleBiasTest(TempDirTestCase):
    def test_the_shift_of_the_large_keypoints_is_found(self):
        text, database = write_case(self.tmp, KB)
        cells = bias.binned(bias.observations(text, database))
        small = [mean for _, j, count, mean in cells if j == 0 and count]
        large = [mean for _, j, count, mean in cells if j == 3 and count]
        self.assertTrue(small and large, cells)
        for mean in small:
            if not np.isnan(mean):
                self.assertAlmostEqual(mean, 0, delta=1e-3)
        measured = [m for m in large if not np.isnan(m)]
        self.assertTrue(measured, cells)
        for mean in measured:
            # float32 keypoints: a few 1e-5 px of rounding.
            self.assertAlmostEqual(mean, SHIFT_PX, delta=1e-3)

    def test_projections_match_the_camera_models(self):
        """Each projection is the model's: a point on the axis lands on the
        principal point, and EUCM with alpha 0 is the pinhole."""
        X = np.array([[0.0, 0.0, 2.0], [0.3, -0.2, 1.0]])
        for model, params in (
                ("OPENCV_FISHEYE", KB[3]),
                ("DOUBLE_SPHERE", [300, 310, 500, 490, -0.2, 0.6]),
                ("EUCM", [300, 310, 500, 490, 0.6, 1.1]),
                ("PINHOLE", [300, 310, 500, 490])):
            uv, centre = bias.project(model, params, X)
            self.assertAlmostEqual(uv[0, 0], centre[0], delta=1e-9, msg=model)
            self.assertAlmostEqual(uv[0, 1], centre[1], delta=1e-9, msg=model)
        pinhole, _ = bias.project("PINHOLE", [300, 310, 500, 490], X)
        eucm, _ = bias.project("EUCM", [300, 310, 500, 490, 0.0, 1.0], X)
        np.testing.assert_allclose(eucm, pinhole, atol=1e-9)
        # Kannala-Brandt without distortion is equidistant.
        kb, _ = bias.project("OPENCV_FISHEYE", [300, 300, 500, 500, 0, 0, 0,
                                                0], X[1:])
        theta = np.arctan2(np.hypot(0.3, 0.2), 1.0)
        self.assertAlmostEqual(np.hypot(*(kb[0] - 500)), 300 * theta,
                               delta=1e-9)

    def test_the_script_writes_its_table_csv_and_plot(self):
        text, database = write_case(self.tmp, KB)
        out = self.path("out")
        result = subprocess.run(
            [sys.executable, os.path.join(REPO_ROOT, "scripts",
                                          "keypoint_scale_bias.py"),
             "--model", text, "--database", database, "--output_dir", out],
            capture_output=True, text=True, check=False)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("| radius, px | 0-2 px |", result.stdout)
        self.assertTrue(os.path.exists(os.path.join(out, "scale_bias.png")))
        with open(os.path.join(out, "scale_bias.csv")) as f:
            self.assertGreater(len(f.readlines()), 2)

    def test_an_unknown_model_is_named(self):
        with self.assertRaises(SystemExit) as raised:
            bias.project("FOV", [1, 1, 0, 0, 0.5], np.ones((1, 3)))
        self.assertIn("FOV", str(raised.exception))


if __name__ == "__main__":
    unittest.main()
