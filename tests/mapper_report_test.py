"""The mapper's per-image report: every image of the run is accounted for,
registered in a model or named with the reason it is in none (no keypoints,
no verified pair, no pose), a split into several models is pointed out, and a
run that makes no model exits non-zero with the same report."""
import os
import re

from cli_util import (Database, TempDirTestCase, main_with_render,
                      write_noise_image)
from sphera_common import (extract_features, match_exhaustive, run_colmap,
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
        database = self.extract_and_match(images)
        result = self.run_mapper(database, images)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("Mapper report: 0 of 3 images registered, in 0 model(s)",
                      result.stdout)
        for name in ("blank.pgm", "noise1.pgm", "noise2.pgm"):
            self.assertIn(f"{name}: not registered: ", result.stdout)
        self.assertIn("Failed to create any sparse model", result.stdout)


if __name__ == "__main__":
    main_with_render()
