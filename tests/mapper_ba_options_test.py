"""SPHERA's bundle adjustment options of the mapper, on one rendered set of
9 panoramas (extracted and matched once):
--Mapper.camera_only_ba_tau_px: after the final global refinement the cameras
are refined over the reliable points only (every observation within tau),
and the model keeps just those points;
--Mapper.ba_sphere_residual / --BundleAdjustment.sphere_residual: the
angular (default) or the pixel residual for the sphere camera models."""
import json
import os
import re
import shutil
import tempfile

from cli_util import TempDirTestCase, main_with_render
from sphera_common import (extract_features, match_exhaustive,
                           model_to_text, read_text_model, run_colmap,
                           run_render)


class MapperBAOptionsTest(TempDirTestCase):
    @classmethod
    def setUpClass(cls):
        cls.shared = tempfile.mkdtemp(prefix="sphera_test_")
        cls.scene = os.path.join(cls.shared, "scene")
        run_render(cls.scene, "--layout", "room9", "--model",
                   "EQUIRECTANGULAR", "--width", "1024", "--height", "512",
                   "--supersample", "2", "--seed", "11")
        cls.images = os.path.join(cls.scene, "images")
        cls.database = os.path.join(cls.shared, "database.db")
        extract_features(cls.database, cls.images, "EQUIRECTANGULAR")
        match_exhaustive(cls.database)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.shared, ignore_errors=True)

    def map(self, name, *options):
        sparse = self.path(name)
        os.makedirs(sparse)
        log = run_colmap("mapper", "--database_path", self.database,
                         "--image_path", self.images, "--output_path", sparse,
                         *options).stdout
        return os.path.join(sparse, "0"), log

    def evaluate(self, model, name):
        output = self.path(name)
        os.makedirs(output)
        run_colmap("model_evaluator", "--gt_path",
                   os.path.join(self.scene, "sparse_gt"), "--input_path",
                   model, "--output_path", output,
                   "--alignment", "orientations")
        with open(os.path.join(output, "evaluation.json")) as f:
            return json.load(f)

    def bundle_adjust(self, model, name, residual):
        output = self.path(name)
        os.makedirs(output)
        run_colmap("bundle_adjuster", "--input_path", model, "--output_path",
                   output, "--BundleAdjustment.sphere_residual", residual)
        _, images, _ = read_text_model(model_to_text(output, output + "_txt"))
        return {fields[9]: [float(v) for v in fields[1:8]]
                for fields, _ in images.values()}

    def test_final_camera_only_refinement(self):
        tau_px = 1.0
        model, log = self.map("sparse", "--Mapper.camera_only_ba_tau_px",
                              tau_px)
        match = re.search(r"Camera-only bundle adjustment \(tau 1 px\): \d+ "
                          r"iterations, points (\d+) -> (\d+), mean error "
                          r"([0-9.e-]+) -> ([0-9.e-]+) px", log)
        self.assertIsNotNone(match, log[-3000:])
        points_before, points_after = int(match[1]), int(match[2])
        self.assertLess(points_after, points_before)
        self.assertGreater(points_after, 0.5 * points_before)

        result = self.evaluate(model, "eval")
        self.assertEqual(result["num_registered"], 9)
        self.assertEqual(result["num_points3D"], points_after)
        self.assertLess(result["mean_rotation_error_deg"], 0.05)
        # Every kept observation is within tau (pixel equivalents).
        self.assertLess(result["mean_angular_error_px"], tau_px)

    def test_sphere_residual_is_selectable(self):
        for residual in ("angular", "pixel"):
            model, _ = self.map("sparse_" + residual,
                                "--Mapper.ba_sphere_residual", residual)
            result = self.evaluate(model, "eval_" + residual)
            self.assertEqual(result["num_registered"], 9, residual)
            self.assertLess(result["mean_rotation_error_deg"], 0.05, residual)

        # The same model refined with each residual: the pixel optimum
        # differs from the angular one by far more than a repeated run does.
        angular = self.bundle_adjust(model, "ba_angular", "angular")
        repeated = self.bundle_adjust(model, "ba_angular_again", "angular")
        pixel = self.bundle_adjust(model, "ba_pixel", "pixel")

        def difference(a, b):
            return max(abs(x - y) for name in a for x, y in zip(a[name],
                                                                  b[name]))

        self.assertEqual(sorted(angular), sorted(pixel))
        self.assertGreater(difference(angular, pixel),
                           100 * difference(angular, repeated) + 1e-9)

        # A bad value is named and nothing is written.
        os.makedirs(self.path("bad"))
        result = run_colmap("mapper", "--database_path", self.database,
                            "--image_path", self.images, "--output_path",
                            self.path("bad"), "--Mapper.ba_sphere_residual",
                            "geodesic", check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("ba_sphere_residual", result.stdout)
        self.assertEqual(os.listdir(self.path("bad")), [])
        result = run_colmap("bundle_adjuster", "--input_path", model,
                            "--output_path", self.path("bad"),
                            "--BundleAdjustment.sphere_residual", "geodesic",
                            check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("sphere_residual", result.stdout)
        self.assertEqual(os.listdir(self.path("bad")), [])


if __name__ == "__main__":
    main_with_render()
