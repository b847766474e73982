"""scripts/demo.sh --camera NAME DIR: one command from a 360° camera's own
files to a rig model. Raw side-by-side dual-fisheye frames rendered by
sphera_render (the generic preset) and, when ../shared/data is present, the
GoPro Fusion's front and back folders (its preset) are split, extracted
with their masks, configured as a rig, matched, checked against the rig
config (colmap rig_check), mapped and calibrated; the demo prints one line
per stage and a summary with the lens poses in the rig. An unknown camera
lists the known ones."""
import os
import re
import shutil

from cli_util import TempDirTestCase, main_with_render
from demo_test import MAX_LINES, run_demo
from sphera_common import (REPO_ROOT, axis_rotation, model_counts,
                           model_to_text, quaternion_from_matrix,
                           run_colmap, run_render, sensors_by_folder)

FUSION_3K = os.path.abspath(os.path.join(
    REPO_ROOT, "..", "shared", "data", "real_cameras", "gopro_fusion_3k"))


def registered(output):
    """(images in the largest model, images, models) of the mapping line."""
    match = re.search(r"mapping: +(\d+) of (\d+) images registered in "
                      r"(?:(1) model|the largest of (\d+) models)", output)
    if not match:
        return None
    largest, total, one, several = match.groups()
    return int(largest), int(total), int(one or several)


def check_axis_readings(test, output):
    """The demo names a lens whose axis the mapper (rig_calibration) and the
    matches inside frames (rig_check) put more than 2° apart, and only
    such a lens; returns the lenses' angles."""
    import numpy as np
    number = r"(-?[0-9.]+)"
    axis = rf"azimuth {number} deg, elevation {number}"
    mapped = {lens: tuple(map(float, m)) for lens, *m in re.findall(
        rf"^(lens[0-9]+): turned .*its axis at {axis}", output,
        re.MULTILINE)}
    checked = {lens: tuple(map(float, c)) for lens, *c in re.findall(
        rf"^(lens[0-9]+): matches inside frames put its axis at {axis}",
        output, re.MULTILINE)}
    angles = {}
    for lens in set(mapped) & set(checked):
        (a1, e1), (a2, e2) = (np.radians(mapped[lens]),
                              np.radians(checked[lens]))
        cosine = (np.sin(e1) * np.sin(e2)
                  + np.cos(e1) * np.cos(e2) * np.cos(a1 - a2))
        angles[lens] = float(np.degrees(np.arccos(min(1.0, cosine))))
        named = re.search(rf"^{lens}: the two readings of its axis are "
                          rf"([0-9.]+) deg apart", output, re.MULTILINE)
        if angles[lens] > 2.05:
            test.assertIsNotNone(named, output)
            test.assertAlmostEqual(float(named.group(1)), angles[lens],
                                   delta=0.06)
        elif angles[lens] < 1.95:
            test.assertIsNone(named, output)
    return angles


def back_lens_pose(model):
    """(R sensor_from_rig, centre in the rig) of MODEL's back lens (its
    images under lens1/)."""
    rotation, translation = sensors_by_folder(
        model_to_text(model, model + "_text"))["lens1"]
    return rotation, -rotation.T @ translation


def angle_deg(u, v):
    """The angle in degrees between vectors U and V."""
    import numpy as np
    cos = np.dot(u, v) / (np.linalg.norm(u) * np.linalg.norm(v))
    return float(np.degrees(np.arccos(np.clip(cos, -1, 1))))


def turn_deg(a, b):
    """The angle in degrees between rotation matrices A and B."""
    import numpy as np
    cos = (np.trace(a.T @ b) - 1) / 2
    return float(np.degrees(np.arccos(np.clip(cos, -1, 1))))


def back_lens_turn(output):
    match = re.search(r"^lens1: turned ([0-9.]+) deg from lens0", output,
                      re.MULTILINE)
    return float(match.group(1)) if match else None


class DemoCameraTest(TempDirTestCase):
    def assert_rig_stages(self, output, lens_images, frames):
        self.assertLessEqual(len(output.splitlines()), MAX_LINES, output)
        self.assertIn(f"splitting:          {lens_images} lens images and "
                      "their masks", output)
        self.assertIn(f"rig configuration:  1 rig(s), {frames} frames",
                      output)
        self.assertIn("rig check:          the lens directions agree",
                      output)
        self.assertIn("--- the rig (colmap rig_calibration) ---", output)

    def fusion_3k_demo(self, camera):
        """The demo's output on the shared GoPro Fusion 3K folders with
        --camera CAMERA, after checking its stages; skips without them."""
        if not os.path.isdir(FUSION_3K):
            self.skipTest(f"{FUSION_3K} is absent (../shared/data)")
        result = run_demo(self.path("demo"), "--camera", camera, FUSION_3K)
        self.assertEqual(result.returncode, 0, result.stdout)
        self.assert_rig_stages(result.stdout, 10, 5)
        return result.stdout

    def test_raw_dual_fisheye_frames_become_a_rig_model(self):
        # Two back-to-back 200° lenses side by side in 640x320 frames.
        scene = self.path("scene")
        run_render(scene, "--rig_preset", "dual_fisheye", "--raw",
                   "--frames", "6", "--lens_size", "320", "--supersample",
                   "1", "--seed", "2")
        result = run_demo(self.path("demo"), "--camera", "dual_fisheye",
                          os.path.join(scene, "raw"))
        output = result.stdout
        self.assertEqual(result.returncode, 0, output)
        self.assert_rig_stages(output, 12, 6)
        self.assertEqual(registered(output), (12, 12, 1), output)
        # The back lens faces the other way (the rendered rig: 180°).
        turn = back_lens_turn(output)
        self.assertIsNotNone(turn, output)
        self.assertGreater(turn, 150, output)
        check_axis_readings(self, output)
        # The lengths are the rig config's scale, and the summary says so.
        self.assertIn("lengths in the model's units: the mapper scales a "
                      "rig model so that its lens offsets are on average "
                      "the rig config's", output)

        # Mapped with the lens offsets held, from the rendered rig's config
        # (its lenses' intrinsics, held) with the back lens turned 2° and
        # set 5 mm aside: its centre stays the config's while its rotation
        # is refined to within 0.5° of the rendered one (0.2° here; free,
        # the offset goes back too and the rotation to 0.02°); every image
        # registered.
        import json
        import numpy as np
        true_rotation, true_centre = back_lens_pose(
            os.path.join(scene, "sparse_gt"))
        turn = np.array(axis_rotation(1, np.radians(2)))
        start_rotation = true_rotation @ turn
        start_centre = true_centre + np.array([0.005, 0, 0])
        with open(os.path.join(scene, "rig_config.json")) as f:
            config = json.load(f)
        back = config[0]["cameras"][1]
        back["cam_from_rig_rotation"] = list(
            quaternion_from_matrix(start_rotation))
        back["cam_from_rig_translation"] = list(
            -start_rotation @ start_centre)
        with open(self.path("off_config.json"), "w") as f:
            json.dump(config, f)
        database = self.path("off.db")
        shutil.copy(self.path("demo", "database.db"), database)
        run_colmap("rig_configurator", "--database_path", database,
                   "--rig_config_path", self.path("off_config.json"))
        held = self.path("offsets_held")
        os.makedirs(held)
        run_colmap("mapper", "--database_path", database, "--image_path",
                   self.path("demo", "split", "images"), "--output_path",
                   held, "--Mapper.random_seed", "0",
                   "--Mapper.ba_refine_focal_length", "0",
                   "--Mapper.ba_refine_extra_params", "0",
                   "--Mapper.ba_refine_sensor_from_rig_translation", "0")
        self.assertEqual(sorted(os.listdir(held)), ["0"])
        self.assertEqual(model_counts(os.path.join(held, "0"))[0], 12)
        rotation, centre = back_lens_pose(os.path.join(held, "0"))
        self.assertLess(np.linalg.norm(centre - start_centre), 1e-9)
        self.assertLess(turn_deg(rotation, true_rotation), 0.5)
        # bundle_adjuster holds them the same way; free, the back lens's
        # centre turns back towards the rendered one's direction (its
        # length is the model's scale, which the held offset set).
        for refine in ("0", "1"):
            adjusted = self.path("adjusted_" + refine)
            os.makedirs(adjusted)
            run_colmap("bundle_adjuster", "--input_path",
                       os.path.join(held, "0"), "--output_path", adjusted,
                       "--BundleAdjustment.refine_focal_length", "0",
                       "--BundleAdjustment.refine_extra_params", "0",
                       "--BundleAdjustment.refine_sensor_from_rig_translation",
                       refine)
            _, adjusted_centre = back_lens_pose(adjusted)
            print(f"offsets refined {refine}: centre {adjusted_centre}, "
                  f"{angle_deg(adjusted_centre, true_centre):.3f} deg from "
                  "the rendered one's direction")
            if refine == "0":
                self.assertLess(
                    np.linalg.norm(adjusted_centre - start_centre), 1e-9)
            else:
                self.assertLess(angle_deg(adjusted_centre, true_centre),
                                angle_deg(start_centre, true_centre) / 2)

    def test_unknown_camera_lists_the_known_ones(self):
        os.makedirs(self.path("frames"))
        result = run_demo(self.path("demo"), "--camera", "no_such_camera",
                          self.path("frames"))
        self.assertNotEqual(result.returncode, 0, result.stdout)
        self.assertIn('no camera preset "no_such_camera"', result.stdout)
        self.assertIn("gopro_fusion", result.stdout)

    def test_gopro_fusion_folders_become_a_rig_model(self):
        output = self.fusion_3k_demo("gopro_fusion")
        mapping = registered(output)
        self.assertIsNotNone(mapping, output)
        count, total, _ = mapping
        self.assertEqual(total, 10, output)
        # The demo's seed 0: 6 of 10 in the largest model (3 of the 5
        # mostly rotating frames), as the preset run in docs/rigs.md.
        self.assertGreaterEqual(count, 6, output)
        self.assertIsNotNone(back_lens_turn(output), output)
        # The matches inside the frames put the back lens's axis within 1°
        # of 180° about the vertical (colmap rig_check, before mapping).
        match = re.search(r"^lens1: matches inside frames put its axis at "
                          r"azimuth (-?[0-9.]+) deg, elevation (-?[0-9.]+) "
                          r"deg$", output, re.MULTILINE)
        self.assertIsNotNone(match, output)
        self.assertGreater(abs(float(match.group(1))), 179, output)
        # Both readings of the back lens's axis are printed; when they part
        # by more than 2° the demo says so.
        self.assertIn("lens1", check_axis_readings(self, output))

        # A short capture's self-calibration can split the run: the demo
        # then maps again with the preset's intrinsics held and keeps that
        # run only when its largest model holds more images. Which run wins
        # differs between machines for the same seed (here the refined run
        # splits 6 + 6; on another, it registered all 10), so the test
        # checks the rule, not one outcome.
        held = re.search(r"^  intrinsics held:  (\d+) of 10 images "
                         r"registered in .* \((kept|not kept);", output,
                         re.MULTILINE)
        if count < 10:
            self.assertIsNotNone(held, output)
        if held:
            held_count = int(held.group(1))
            kept = held.group(2) == "kept"
            self.assertEqual(kept, held_count > count, output)
            final = max(count, held_count)
        else:
            final = count
        self.assertRegex(output, rf"(?m)^[0-9]+: Registered images: {final}$")

        # The global mapper keeps the rig's lenses at the preset's
        # intrinsics (refined, every track was filtered): all 10 images.
        global_sparse = self.path("sparse_global")
        os.makedirs(global_sparse)
        run_colmap(
            "global_mapper", "--database_path",
            self.path("demo", "database.db"), "--image_path",
            self.path("demo", "split", "images"), "--output_path",
            global_sparse, "--GlobalMapper.random_seed", "0")
        images, points = model_counts(os.path.join(global_sparse, "0"))
        self.assertEqual(images, 10)
        self.assertGreater(points, 100)

    def test_gopro_fusion_folders_with_the_circles_detected(self):
        """The generic preset on the same folders: the splitter detects
        each lens's circle in the frames, the lenses start 3 cm apart, and
        the frames map as a rig (6 of 10 images: frames 4 and 5 alone
        start no second model; docs/rigs.md)."""
        output = self.fusion_3k_demo("dual_fisheye")
        with open(self.path("demo", "demo.log")) as log:
            detected = re.findall(r"lens[01]: image circle \(cx, cy, r\) = "
                                  r"\(([0-9.]+), ([0-9.]+), ([0-9.]+)\) "
                                  r"detected", log.read())
        self.assertEqual(len(detected), 2, output)
        for cx, cy, r in detected:
            # Near the circle of the maker's 3K parameter file.
            self.assertLess(abs(float(cx) - 779), 20)
            self.assertLess(abs(float(cy) - 742), 20)
            self.assertLess(abs(float(r) - 765), 20)
        mapping = registered(output)
        self.assertIsNotNone(mapping, output)
        self.assertGreaterEqual(mapping[0], 6, output)
        self.assertIsNotNone(back_lens_turn(output), output)


if __name__ == "__main__":
    main_with_render()
