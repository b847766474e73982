"""`colmap dual_fisheye_splitter`: raw dual-fisheye frames ([lens0 | lens1]
side by side) become one image per lens, exact pixels inside the image
circle and black outside, plus circle masks, rig_config.json and
circles.txt, which feature_extractor and rig_configurator take as they are.
Bad input (a normal photo, an odd width, a circle outside its lens image, an
unreadable file, an empty folder, existing outputs) fails with a message
naming it and leaves nothing behind.

Images are written and read with PIL (a dependency of matplotlib, which
scripts/setup.sh installs); the command reads and writes with OpenCV."""
import json
import os
import shutil
import unittest

import numpy as np
from PIL import Image

from cli_util import Database, TempDirTestCase, listing
from sphera_common import CPU_EXTRACTION, run_colmap

# Lens images W x H (not square, to catch a swapped axis) and image circles
# (cx, cy, r) in lens image pixels.
LENS_W, LENS_H = 96, 88
CIRCLES = [(47.3, 43.6, 40.2), (49.0, 44.25, 42.5)]


def inside_mask(width, height, circle):
    """The stated rule: pixel (x, y) is inside iff
    (x+0.5-cx)^2 + (y+0.5-cy)^2 <= r^2, in double."""
    cx, cy, r = circle
    x = np.arange(width, dtype=np.float64) + 0.5 - cx
    y = np.arange(height, dtype=np.float64) + 0.5 - cy
    return (x * x)[np.newaxis, :] + (y * y)[:, np.newaxis] <= r * r


def make_raw(seed, circles=CIRCLES, channels=3, width=LENS_W, height=LENS_H,
             dtype=np.uint8):
    """A raw frame: smooth texture above the black level inside each image
    circle, black (0) outside."""
    rng = np.random.default_rng(seed)
    top = 65535 if dtype == np.uint16 else 255
    shape = (height, 2 * width) + ((channels,) if channels > 1 else ())
    coarse = rng.uniform(0.15, 1.0, size=(height // 8 + 1, 2 * width // 8 + 1)
                         + shape[2:])
    texture = np.repeat(np.repeat(coarse, 8, axis=0), 8, axis=1)
    texture = texture[:height, :2 * width]
    texture = texture * rng.uniform(0.8, 1.0, size=shape)
    raw = (texture * top).astype(dtype)
    for lens, circle in enumerate(circles):
        outside = ~inside_mask(width, height, circle)
        raw[:, lens * width:(lens + 1) * width][outside] = 0
    return raw


def save(path, array):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    Image.fromarray(array).save(path)


def load(path):
    with Image.open(path) as image:
        return np.array(image)


def circles_arg(circles):
    return ";".join(",".join(repr(v) for v in c) for c in circles)


class DualFisheyeSplitterTest(TempDirTestCase):
    def split(self, *args, check=True, input_path=None, output=None):
        return run_colmap("dual_fisheye_splitter",
                          "--input_path", input_path or self.path("raw"),
                          "--output_path", output or self.path("out"),
                          *args, check=check)

    def assert_refused(self, needles, *args, input_path=None):
        """The command fails naming every one of NEEDLES; --output_path is
        not created and no temporary file is left anywhere."""
        output = self.path("refused")
        result = self.split(*args, check=False, input_path=input_path,
                            output=output)
        self.assertNotEqual(result.returncode, 0, result.stdout)
        for needle in needles:
            self.assertIn(needle, result.stdout)
        self.assertFalse(os.path.exists(output), result.stdout)
        leftovers = [p for p in listing(self.tmp) if ".tmp-" in p]
        self.assertEqual(leftovers, [])
        return result.stdout

    def assert_split(self, output, name, raw, circles, lens_names=("lens0",
                                                                   "lens1")):
        """The lens images of NAME are RAW's halves exactly inside CIRCLES
        and black outside; the masks are the circles."""
        for lens, lens_name in enumerate(lens_names):
            inside = inside_mask(LENS_W, LENS_H, circles[lens])
            half = raw[:, lens * LENS_W:(lens + 1) * LENS_W]
            expected = half.copy()
            expected[~inside] = 0
            image = load(os.path.join(output, "images", lens_name, name))
            self.assertEqual(image.shape, expected.shape, name)
            np.testing.assert_array_equal(image, expected,
                                          err_msg=f"{lens_name}/{name}")
            with Image.open(os.path.join(output, "masks", lens_name,
                                         name + ".png")) as mask:
                self.assertEqual(mask.mode, "L")
                np.testing.assert_array_equal(
                    np.array(mask), np.where(inside, 255, 0),
                    err_msg=f"mask {lens_name}/{name}")

    def read_circles(self, output):
        """{lens: (cx, cy, r)} of circles.txt: a comment line, then one line
        per lens."""
        with open(os.path.join(output, "circles.txt")) as f:
            lines = f.read().splitlines()
        self.assertTrue(lines[0].startswith("#"), lines[0])
        self.assertEqual(len(lines), 3)
        fields = [line.split() for line in lines[1:]]
        return {f[0]: tuple(map(float, f[1:])) for f in fields}

    def test_split_with_given_circles(self):
        raws = {"a.png": make_raw(1), "sub/b.png": make_raw(2),
                "gray.png": make_raw(3, channels=1),
                "deep.png": make_raw(4, channels=1, dtype=np.uint16)}
        for name, raw in raws.items():
            save(self.path("raw", name), raw)
        with open(self.path("raw", "notes.txt"), "w") as f:
            f.write("not an image\n")
        output = self.path("out")
        result = self.split("--circles", circles_arg(CIRCLES))
        self.assertIn("4 raw frames -> 8 lens images and masks (96x88)",
                      result.stdout)

        expected_files = {"rig_config.json", "circles.txt"}
        for lens in ("lens0", "lens1"):
            for name in raws:
                expected_files.add(f"images/{lens}/{name}")
                expected_files.add(f"masks/{lens}/{name}.png")
        files = {p for p, size in listing(output).items() if size >= 0}
        self.assertEqual(files, expected_files)
        for name, raw in raws.items():
            self.assert_split(output, name, raw, CIRCLES)
        # 16 bits stay 16 bits (the bit depth in the PNG header).
        with open(self.path("out", "images", "lens0", "deep.png"), "rb") as f:
            self.assertEqual(f.read(25)[24], 16)

        self.assertEqual(self.read_circles(output),
                         {"lens0": CIRCLES[0], "lens1": CIRCLES[1]})
        with open(os.path.join(output, "rig_config.json")) as f:
            config = json.load(f)
        self.assertEqual(config, [{"cameras": [
            {"image_prefix": "lens0/", "ref_sensor": True},
            {"image_prefix": "lens1/", "cam_from_rig_rotation": [0, 0, 1, 0],
             "cam_from_rig_translation": [0, 0, 0]}]}])

        # A second run refuses to overwrite, names a file, changes nothing.
        before = listing(output)
        result = self.split("--circles", circles_arg(CIRCLES), check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("refusing to overwrite", result.stdout)
        self.assertIn(os.path.join("images", "lens0", "a.png"), result.stdout)
        self.assertEqual(listing(output), before)

    def test_detected_circles_and_rig_configurator(self):
        raws = {f"frame{i}.png": make_raw(10 + i) for i in range(3)}
        for name, raw in raws.items():
            save(self.path("raw", name), raw)
        # A JPEG frame stays a JPEG under its own name.
        # (No chroma subsampling: it would smear colour over the black
        # surround, a large part of it in images this small.)
        Image.fromarray(make_raw(20)).save(self.path("raw", "photo.jpg"),
                                           quality=98, subsampling=0)
        with open(self.path("list.txt"), "w") as f:
            f.write("frame0.png\n\nframe2.png\nphoto.jpg\n")
        params = "60,60,48,44,0.01,0,0,0"
        output = self.path("out")
        result = self.split("--image_list_path", self.path("list.txt"),
                            "--lens_names", "front,back",
                            "--camera_model", "OPENCV_FISHEYE",
                            "--camera_params", params)
        self.assertIn("median of 3 of 3 frames", result.stdout)

        circles = self.read_circles(output)
        self.assertEqual(sorted(circles), ["back", "front"])
        for lens_name, true_circle in zip(("front", "back"), CIRCLES):
            for got, true in zip(circles[lens_name], true_circle):
                self.assertLess(abs(got - true), 1.0, (lens_name, got, true))
        detected = [circles["front"], circles["back"]]
        for name in ("frame0.png", "frame2.png"):
            self.assert_split(output, name, raws[name], detected,
                              lens_names=("front", "back"))
        self.assertFalse(os.path.exists(os.path.join(
            output, "images", "front", "frame1.png")))
        with Image.open(os.path.join(output, "images", "back",
                                     "photo.jpg")) as image:
            self.assertEqual(image.format, "JPEG")
            self.assertEqual(image.size, (LENS_W, LENS_H))

        with open(os.path.join(output, "rig_config.json")) as f:
            config = json.load(f)
        cameras = config[0]["cameras"]
        self.assertEqual([c["image_prefix"] for c in cameras],
                         ["front/", "back/"])
        for camera in cameras:
            self.assertEqual(camera["camera_model_name"], "OPENCV_FISHEYE")
            self.assertEqual(camera["camera_params"],
                             [float(v) for v in params.split(",")])

        # COLMAP takes the layout as it is: masks by image name; one rig of
        # a reference sensor and one more (rig_sensors holds the others), one
        # frame of two images per raw frame, the cameras of rig_config.json.
        database = self.path("database.db")
        run_colmap("feature_extractor", "--database_path", database,
                   "--image_path", os.path.join(output, "images"),
                   "--ImageReader.mask_path", os.path.join(output, "masks"),
                   "--ImageReader.single_camera_per_folder", "1",
                   *CPU_EXTRACTION)
        run_colmap("rig_configurator", "--database_path", database,
                   "--rig_config_path",
                   os.path.join(output, "rig_config.json"))
        db = Database(database)
        try:
            self.assertEqual(db.scalar("SELECT COUNT(*) FROM images"), 6)
            self.assertEqual(db.scalar("SELECT COUNT(*) FROM rigs"), 1)
            self.assertEqual(db.scalar("SELECT COUNT(*) FROM rig_sensors"), 1)
            self.assertEqual(db.scalar("SELECT COUNT(*) FROM frames"), 3)
            self.assertEqual(db.scalar("SELECT COUNT(*) FROM frame_data"), 6)
            cameras = db.cameras()
            self.assertEqual(len(cameras), 2)
            for _, width, height, camera_params in cameras.values():
                self.assertEqual((width, height), (LENS_W, LENS_H))
                self.assertEqual(camera_params,
                                 [float(v) for v in params.split(",")])
        finally:
            db.close()

    def test_bad_input(self):
        good = make_raw(30)
        save(self.path("raw", "good.png"), good)
        given = ["--circles", circles_arg(CIRCLES)]

        # An odd width.
        save(self.path("raw", "odd.png"), make_raw(31)[:, :-1])
        self.assert_refused(["odd.png", "odd width"], *given)
        self.assert_refused(["odd.png", "odd width"])
        os.remove(self.path("raw", "odd.png"))

        # A normal photo of the same 2:1 size (texture everywhere), found with
        # the given circles and with the detected ones.
        rng = np.random.default_rng(5)
        photo = rng.integers(20, 256, size=good.shape, dtype=np.uint8)
        save(self.path("raw", "sub", "photo.png"), photo)
        self.assert_refused(["sub/photo.png", "not a dual-fisheye frame"],
                            *given)
        self.assert_refused(["sub/photo.png", "not a dual-fisheye frame"])
        # Alone, no image circle is found in it.
        self.assert_refused(["photo.png", "no image circle"],
                            input_path=self.path("raw", "sub"))
        shutil.rmtree(self.path("raw", "sub"))

        # A circle outside its lens image, given or detected.
        too_big = [CIRCLES[0], (49.0, 44.25, 46.0)]
        self.assert_refused(["lens1", "(cx, cy, r) = (49, 44.25, 46)",
                             "goes outside the 96x88 lens image"],
                            "--circles", circles_arg(too_big))
        off_side = [(20.0, 44.0, 30.0), CIRCLES[1]]
        save(self.path("cut", "cut.png"), make_raw(32, circles=off_side))
        self.assert_refused(["lens0", "goes outside the 96x88 lens image"],
                            input_path=self.path("cut"))
        self.assert_refused(["--circles", "expected two circles"],
                            "--circles", "1,2,3")

        # An unreadable image, among good ones.
        with open(self.path("raw", "broken.png"), "wb") as f:
            f.write(b"\x89PNG\r\n\x1a\nnot really")
        self.assert_refused(["broken.png", "cannot read"], *given)
        os.remove(self.path("raw", "broken.png"))

        # Frames of two sizes.
        save(self.path("raw", "small.png"),
             make_raw(33, width=48, height=40,
                      circles=[(24, 20, 15), (24, 20, 15)]))
        self.assert_refused(["small.png", "96x40", "192x88"], *given)
        os.remove(self.path("raw", "small.png"))

        # An empty folder; a list naming a missing file.
        os.makedirs(self.path("empty"))
        self.assert_refused(["no raw frames", self.path("empty")],
                            input_path=self.path("empty"))
        with open(self.path("list.txt"), "w") as f:
            f.write("good.png\nmissing.png\n")
        self.assert_refused(["missing.png", "no such file"],
                            "--image_list_path", self.path("list.txt"))

        # Bad options.
        self.assert_refused(["--lens_names"], "--lens_names", "a")
        self.assert_refused(["--lens_names"], "--lens_names", "a,a")
        self.assert_refused(["--lens_names", "a/b"], "--lens_names", "a/b,c")
        self.assert_refused(["--camera_model and --camera_params"],
                            "--camera_model", "OPENCV_FISHEYE")
        self.assert_refused(["NO_SUCH_MODEL"], "--camera_model",
                            "NO_SUCH_MODEL", "--camera_params", "1,2,3")
        self.assert_refused(["--camera_params", "3 values", "OPENCV_FISHEYE"],
                            "--camera_model", "OPENCV_FISHEYE",
                            "--camera_params", "1,2,3")
        self.assert_refused(["--black_level"], "--black_level", "300")

        # Only good.png is left: it splits.
        self.split(*given)
        self.assert_split(self.path("out"), "good.png", good, CIRCLES)


if __name__ == "__main__":
    unittest.main()
