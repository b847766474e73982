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

from cli_util import TempDirTestCase, main_with_render
from demo_test import MAX_LINES, run_demo
from sphera_common import REPO_ROOT, model_counts, run_colmap, run_render

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
        # The lengths are the rig config's scale, and the summary says so.
        self.assertIn("lengths in the model's units: the mapper scales a "
                      "rig model so that its lens offsets are on average "
                      "the rig config's", output)

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
