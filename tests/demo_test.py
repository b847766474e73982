"""scripts/demo.sh talks like a tool: on a rendered scene (the default
scene's 9 panoramas, smaller) it prints at most 40 lines, one per stage with
its counts, and a summary whose counts agree with the database and the model,
with the errors against the scene's ground truth; COLMAP's output goes to the
log file it names. SPHERA_COLMAP and SPHERA_RENDER (set by ctest) make the
demo skip setup and build."""
import os
import re
import sqlite3
import subprocess

from cli_util import TempDirTestCase, main_with_render
from sphera_common import COLMAP, REPO_ROOT, run_render

DEMO = os.path.join(REPO_ROOT, "scripts", "demo.sh")
MAX_LINES = 40


def run_demo(work_dir, *args, colmap=COLMAP, env_extra=None):
    env = dict(os.environ, SPHERA_DEMO_DIR=work_dir, SPHERA_COLMAP=colmap)
    env.update(env_extra or {})
    return subprocess.run([DEMO, *args], env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, timeout=900,
                          stdin=subprocess.DEVNULL)


class DemoTest(TempDirTestCase):
    def test_rendered_scene_prints_stages_and_summary(self):
        # The default scene at a quarter of its pixels: the same stages and
        # summary in a fraction of the time.
        scene = self.path("scene")
        run_render(scene, "--layout", "room9", "--model", "EQUIRECTANGULAR",
                   "--width", "1024", "--height", "512", "--supersample", "1",
                   "--seed", "1")
        work_dir = self.path("demo")
        result = run_demo(work_dir, os.path.join(scene, "images"))
        output = result.stdout
        self.assertEqual(result.returncode, 0, output)
        lines = output.splitlines()
        self.assertLessEqual(len(lines), MAX_LINES, output)

        log = os.path.join(work_dir, "demo.log")
        self.assertIn("demo: the output of every command goes to " + log,
                      lines[0])
        self.assertEqual(lines[-1], "log: " + log)
        with open(log) as f:
            log_text = f.read()
        # COLMAP's log is in the file, not on the screen.
        for command in ("feature_extractor", "exhaustive_matcher", "mapper"):
            self.assertIn("=== ", log_text)
            self.assertIn(COLMAP + " " + command, log_text)
        self.assertIn("Registering image #", log_text)
        self.assertNotIn("Registering image #", output)

        database = sqlite3.connect(os.path.join(work_dir, "database.db"))
        images = database.execute("SELECT COUNT(*) FROM images").fetchone()[0]
        keypoints = database.execute(
            "SELECT SUM(rows) FROM keypoints").fetchone()[0]
        verified = database.execute(
            "SELECT COUNT(*) FROM two_view_geometries WHERE rows > 0"
        ).fetchone()[0]
        pairs = database.execute("SELECT COUNT(*) FROM matches").fetchone()[0]
        database.close()
        self.assertEqual(images, 9)

        def line(pattern):
            found = [m for m in map(re.compile(pattern).match, lines) if m]
            self.assertEqual(len(found), 1, f"{pattern!r} in\n{output}")
            return found[0]

        extraction = line(r"feature extraction: (\d+) images, (\d+) keypoints")
        self.assertEqual(int(extraction.group(1)), images)
        self.assertEqual(int(extraction.group(2)), keypoints)
        matching = line(r"matching: +(\d+) of (\d+) image pairs verified")
        self.assertEqual(int(matching.group(1)), verified)
        self.assertEqual(int(matching.group(2)), pairs)
        mapping = line(r"mapping: +(\d+) of (\d+) images registered in 1 model")
        self.assertEqual(int(mapping.group(2)), images)
        registered = int(mapping.group(1))
        self.assertEqual(registered, images, output)

        # The summary, as before: counts, the errors against the ground
        # truth (model_evaluator's table) and the model's statistics.
        line(r"=== SPHERA demo summary \(\d+ s\) ===$")
        self.assertEqual(int(line(r"images: +(\d+)$").group(1)), images)
        self.assertEqual(int(line(r"keypoints: +(\d+)$").group(1)), keypoints)
        self.assertEqual(int(line(r"verified pairs: +(\d+)$").group(1)),
                         verified)
        ground_truth = lines.index(
            "--- against the ground truth (colmap model_evaluator) ---")
        evaluator_table = lines[ground_truth + 1:ground_truth + 8]
        self.assertIn("registered: %d/%d" % (registered, images),
                      evaluator_table, output)
        for start in ("rotation error (deg): mean ", "position error: mean ",
                      "reprojection error: mean "):
            self.assertTrue(any(l.startswith(start) for l in evaluator_table),
                            start + " in\n" + output)
        self.assertEqual(int(line(r"0: Registered images: (\d+)$").group(1)),
                         registered)
        self.assertGreater(int(line(r"0: Points: (\d+)$").group(1)), 100)
        error = float(line(r"0: Mean reprojection error: ([0-9.]+)px$")
                      .group(1))
        self.assertLess(error, 2.0)

    def test_failed_stage_names_the_log(self):
        # A program that fails: the demo stops at its first stage, says so
        # and shows the end of the log.
        images = self.path("images")
        os.makedirs(images)
        fake = self.path("colmap")
        with open(fake, "w") as f:
            f.write("#!/bin/sh\necho 'fake colmap: broken on purpose' >&2\n"
                    "exit 3\n")
        os.chmod(fake, 0o755)
        work_dir = self.path("demo")
        result = run_demo(work_dir, images, colmap=fake)
        self.assertEqual(result.returncode, 3, result.stdout)
        log = os.path.join(work_dir, "demo.log")
        self.assertIn("demo: feature extraction failed (exit 3); the end of "
                      + log, result.stdout)
        self.assertIn("fake colmap: broken on purpose", result.stdout)
        with open(log) as f:
            self.assertIn("fake colmap: broken on purpose", f.read())


if __name__ == "__main__":
    main_with_render()
