"""The mapper's per-image report: every image of the run is accounted for,
registered in a model or named with the reason it is in none (no keypoints,
no verified pair, no pose), a split into several models is pointed out, and a
run that makes no model exits non-zero with the same report; a camera whose
self-calibration leaves the bounds --Mapper.hold_focal_ratio /
--Mapper.hold_aspect_change set is held at its value before that bundle
adjustment and named in the report."""
import os
import re

from cli_util import (Database, TempDirTestCase, main_with_render,
                      write_noise_image)
from sphera_common import (extract_features, match_exhaustive,
                           model_to_text, read_text_cameras, run_colmap,
                           run_render)

WIDTH, HEIGHT = 640, 480


def write_blank_image(path):
    with open(path, "wb") as f:
        f.write(f"P5\n{WIDTH} {HEIGHT}\n255\n".encode())
        f.write(bytes([128]) * (WIDTH * HEIGHT))


class MapperReportTest(TempDirTestCase):
    def extract_and_match(self, image_path):
        database = self.path("database.db")
        extract_features(database, image_path, "PINHOLE",
                         params=[320, 320, 320, 240])
        match_exhaustive(database)
        return database

    def run_mapper(self, database, image_path, output="sparse",
                   min_model_size=4):
        """min_model_size 4 keeps the second arc's model of 4 images. The
        default, 10, drops it: COLMAP lowers the minimum to half the images
        with matches, 6 here, still above 4.
        The ring's neighbours are close together: a lower initial
        triangulation angle than the default 16 degrees lets each arc start
        a model whatever pairs RANSAC verified."""
        os.makedirs(self.path(output))
        return run_colmap("mapper", "--database_path", database,
                          "--image_path", image_path, "--output_path",
                          self.path(output), "--Mapper.min_model_size",
                          min_model_size, "--Mapper.init_min_tri_angle", 4,
                          check=False)

    def test_two_scenes_a_blank_and_a_noise_image(self):
        images = self.path("images")
        # Two arcs of the outward-looking ring (8 and 4 views) that see
        # opposite walls and share no view: two models.
        scene = self.path("scene")
        run_render(scene, "--layout", "ring", "--supersample", "2", "--seed",
                   "3")
        names = sorted(os.listdir(os.path.join(scene, "images")))
        self.assertEqual(len(names), 16)
        os.makedirs(images)
        for name in names[0:8] + names[10:14]:
            os.symlink(os.path.join(scene, "images", name),
                       os.path.join(images, name))
        write_blank_image(os.path.join(images, "blank.pgm"))
        write_noise_image(os.path.join(images, "noise.pgm"), WIDTH, HEIGHT,
                          seed=5)
        database = self.extract_and_match(images)
        db = Database(database)
        num_matches_before = db.scalar("SELECT COUNT(*) FROM matches")
        db.close()

        result = self.run_mapper(database, images)
        log = result.stdout
        self.assertEqual(result.returncode, 0, log[-3000:])
        self.assertEqual(sorted(os.listdir(self.path("sparse"))), ["0", "1"])
        summary = re.search(r"Mapper report: (\d+) of (\d+) images "
                            r"registered, in (\d+) model\(s\)", log)
        self.assertIsNotNone(summary, log[-3000:])
        self.assertEqual(int(summary[2]), 14)
        self.assertEqual(int(summary[3]), 2)
        self.assertIn("The images split into 2 models", log)
        models = [int(m) for m in re.findall(r"  model \d+: (\d+) images", log)]
        self.assertEqual(len(models), 2)
        self.assertEqual(sum(models), int(summary[1]))
        self.assertRegex(log, r"blank\.pgm: not registered: no keypoints")
        self.assertRegex(log, r"noise\.pgm: not registered: no verified "
                              r"image pair with at least 15 inlier matches")
        # Every image the report does not name as unregistered is in a model.
        unregistered = re.findall(r"(\S+): not registered: ", log)
        self.assertEqual(len(unregistered) + int(summary[1]), 14)
        # With the default minimum model size the second arc's model is
        # dropped: its images have verified pairs but are in no model.
        result = self.run_mapper(database, images, "sparse_default", 10)
        self.assertEqual(result.returncode, 0, result.stdout[-3000:])
        self.assertEqual(os.listdir(self.path("sparse_default")), ["0"])
        dropped = re.findall(r"(\S+): not registered: verified pairs with "
                             r"\d+ image\(s\), but no model kept it",
                             result.stdout)
        self.assertEqual(len(dropped), 4, result.stdout[-3000:])
        # The mapper only reads the database.
        db = Database(database)
        self.assertEqual(db.scalar("SELECT COUNT(*) FROM matches"),
                         num_matches_before)
        db.close()

    def test_no_model_exits_non_zero_with_the_report(self):
        images = self.path("images")
        os.makedirs(images)
        write_blank_image(os.path.join(images, "blank.pgm"))
        for seed in (1, 2):
            write_noise_image(os.path.join(images, f"noise{seed}.pgm"), WIDTH,
                              HEIGHT, seed=seed)
        database = self.path("database.db")
        extract_features(database, images, "PINHOLE",
                         params=[320, 320, 320, 240])
        # The matcher already says there is nothing to map, and fails.
        matching = match_exhaustive(
            database, program=lambda *args: run_colmap(*args, check=False))
        self.assertEqual(matching.returncode, 1, matching.stdout[-2000:])
        self.assertRegex(matching.stdout,
                         "no image pair passed geometric verification: of 3 "
                         "pairs matched, (none has the 15 raw matches|"
                         r"\d ha(s|ve) at least 15 raw matches, yet no "
                         "two-view geometry fits any: the images may show "
                         "different scenes)")
        result = self.run_mapper(database, images)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("Mapper report: 0 of 3 images registered, in 0 model(s)",
                      result.stdout)
        for name in ("blank.pgm", "noise1.pgm", "noise2.pgm"):
            self.assertIn(f"{name}: not registered: ", result.stdout)
        self.assertIn("Failed to create any sparse model", result.stdout)


class HeldCameraTest(TempDirTestCase):
    """Nine 195-degree EUCM views of the room, one square-pixel camera that
    starts at its true intrinsics. The mapper refines fx and fy apart by
    noise; a bound on fx / fy tighter than that noise must hold the camera
    at its start, say so in the report, and still reconstruct every view."""

    def map(self, database, images, name, *options):
        sparse = self.path(name)
        os.makedirs(sparse)
        result = run_colmap("mapper", "--database_path", database,
                            "--image_path", images, "--output_path", sparse,
                            *options, check=False)
        return sparse, result

    def final_camera(self, sparse, name):
        cameras = read_text_cameras(model_to_text(
            os.path.join(sparse, "0"), self.path(name + "_txt")))
        self.assertEqual(len(cameras), 1)
        return next(iter(cameras.values()))

    def test_camera_held_at_its_start_and_reported(self):
        scene = self.path("scene")
        run_render(scene, "--layout", "room9", "--model", "EUCM", "--width",
                   "640", "--height", "640", "--supersample", "2", "--seed",
                   "4")
        truth = next(iter(read_text_cameras(
            os.path.join(scene, "sparse_gt")).values()))
        model, width, height, params = truth
        self.assertEqual(model, "EUCM")
        self.assertEqual(params[0], params[1])
        images = os.path.join(scene, "images")
        database = self.path("database.db")
        extract_features(database, images, "EUCM", params=params)
        match_exhaustive(database)

        # Unbounded (the default 20%): fx / fy drifts from 1 by noise.
        sparse, result = self.map(database, images, "free")
        self.assertEqual(result.returncode, 0, result.stdout[-3000:])
        self.assertNotIn("was held", result.stdout)
        free = self.final_camera(sparse, "free")[3]
        drift = abs(free[0] / free[1] - 1)
        self.assertGreater(drift, 1e-7)

        sparse, result = self.map(database, images, "held",
                                  "--Mapper.hold_aspect_change", drift / 10)
        log = result.stdout
        self.assertEqual(result.returncode, 0, log[-3000:])
        self.assertRegex(log, r"Camera 1 \(EUCM\): its self-calibration ran "
                              r"away: a square-pixel lens ended with fx / fy")
        self.assertRegex(log, r"Camera 1 \(EUCM\) was held: its "
                              r"self-calibration ran away \(.*\); it kept ")
        self.assertIn("Mapper report: 9 of 9 images registered, in 1 model(s)",
                      log)
        held = self.final_camera(sparse, "held")[3]
        self.assertLessEqual(abs(held[0] / held[1] - 1), drift / 10)
        # The model keeps the camera the report names, as it was held.
        kept = re.search(r"it kept ([-+0-9.e, ]+?) \(Mapper\.hold_focal_ratio",
                         log)
        self.assertIsNotNone(kept, log[-3000:])
        kept = [float(v) for v in kept[1].split(",")]
        self.assertEqual(len(kept), len(held))
        for value, reported in zip(held, kept):
            self.assertAlmostEqual(value, reported,
                                   delta=1e-5 * abs(reported) + 1e-9)
        # It did not run far before being held: within 1% of its start.
        for value, start in zip(held[:4], params[:4]):
            self.assertAlmostEqual(value, start, delta=0.01 * start)

        # A bound that holds every camera before it moves is refused, named,
        # and nothing is written.
        sparse, result = self.map(database, images, "bad",
                                  "--Mapper.hold_focal_ratio", 1)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("hold_focal_ratio", result.stdout)
        self.assertEqual(os.listdir(sparse), [])


if __name__ == "__main__":
    main_with_render()
