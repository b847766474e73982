"""The mapper's --Mapper.camera_only_ba_tau_px option: after the final
global refinement the cameras are refined over the reliable points only
(every observation within tau), and the model keeps just those points."""
import json
import os
import re
import subprocess

from cli_util import TempDirTestCase, run_colmap

import unittest

RENDER = os.environ.get("SPHERA_RENDER", "")


class MapperCameraOnlyBATest(TempDirTestCase):
    def test_final_camera_only_refinement(self):
        scene = self.path("scene")
        subprocess.run([RENDER, "--output", scene, "--layout", "room9",
                        "--model", "EQUIRECTANGULAR", "--width", "1024",
                        "--height", "512", "--supersample", "2", "--seed",
                        "11"], check=True, stdout=subprocess.DEVNULL)
        database = self.path("database.db")
        run_colmap("feature_extractor", "--database_path", database,
                   "--image_path", os.path.join(scene, "images"),
                   "--ImageReader.camera_model", "EQUIRECTANGULAR",
                   "--ImageReader.single_camera", "1",
                   "--SiftExtraction.use_gpu", "0")
        run_colmap("exhaustive_matcher", "--database_path", database,
                   "--SiftMatching.use_gpu", "0")
        tau_px = 1.0
        os.makedirs(self.path("sparse"))
        log = run_colmap("mapper", "--database_path", database,
                         "--image_path", os.path.join(scene, "images"),
                         "--output_path", self.path("sparse"),
                         "--Mapper.camera_only_ba_tau_px", tau_px).stdout
        match = re.search(r"Camera-only bundle adjustment \(tau 1 px\): \d+ "
                          r"iterations, points (\d+) -> (\d+), mean error "
                          r"([0-9.e-]+) -> ([0-9.e-]+) px", log)
        self.assertIsNotNone(match, log[-3000:])
        points_before, points_after = int(match[1]), int(match[2])
        self.assertLess(points_after, points_before)
        self.assertGreater(points_after, 0.5 * points_before)

        os.makedirs(self.path("eval"))
        run_colmap("model_evaluator", "--gt_path",
                   os.path.join(scene, "sparse_gt"), "--input_path",
                   self.path("sparse", "0"), "--output_path", self.path("eval"))
        with open(self.path("eval", "evaluation.json")) as f:
            result = json.load(f)
        self.assertEqual(result["num_registered"], 9)
        self.assertEqual(result["num_points3D"], points_after)
        self.assertLess(result["mean_rotation_error_deg"], 0.05)
        # Every kept observation is within tau (pixel equivalents).
        self.assertLess(result["mean_angular_error_px"], tau_px)


if __name__ == "__main__":
    if not os.path.exists(RENDER):
        raise SystemExit(f"SPHERA_RENDER={RENDER!r} is not the built renderer")
    unittest.main()
