"""`colmap dual_fisheye_splitter`: raw dual-fisheye frames ([lens0 | lens1]
side by side, or one file per lens in a front and a back folder or with
lens suffixes) become one image per lens, exact pixels inside the image
circle and black outside, plus circle masks, rig_config.json and
circles.txt, which feature_extractor and rig_configurator take as they are.
Image circles may reach past the image's edges (the mask is their part
inside). Bad input (a normal photo, an odd width, an absurd circle, an
unreadable file, an empty folder, a lens file missing, existing outputs)
fails with a message naming it and leaves nothing behind.

The real GoPro Fusion frames of the shared data set (beside the repository)
are split with their maker's circles and with detected ones; those tests
are skipped, saying so, when the data set is absent.

Images are written and read with PIL (a dependency of matplotlib, which
scripts/setup.sh installs); the command reads and writes with OpenCV."""
import json
import os
import re
import shutil
import time
import unittest

import numpy as np
from PIL import Image

from cli_util import SHARED_DATA, Database, TempDirTestCase, listing
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

    def split_folders(self, front, back, output, *args, check=True):
        """The splitter on one folder per lens, FRONT and BACK (below the
        temporary folder)."""
        return run_colmap("dual_fisheye_splitter",
                          "--front_path", self.path(front),
                          "--back_path", self.path(back),
                          "--output_path", output, *args, check=check)

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
        # The output folder it would have made is not a missing path.
        for line in result.stdout.splitlines():
            if "paths that do not exist" in line:
                self.assertNotIn("--output_path", line)
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

    def test_flat_field_divides_out_the_light_fall_off(self):
        """--flat_field 1: each lens's fall-off towards the rim (here the
        renderer's vignetting, 1 - 0.7 rho^2 + 0.35 rho^4, the rim at 65%)
        is estimated from its frames and divided out; without it the lens
        images are the frames' pixels."""
        raws, flats = [], []
        for seed in range(12):
            flat = make_raw(seed)
            raw = flat.astype(np.float64)
            for lens, (cx, cy, r) in enumerate(CIRCLES):
                x = np.arange(LENS_W) + 0.5 - cx
                y = np.arange(LENS_H) + 0.5 - cy
                rho2 = np.minimum((x * x)[np.newaxis, :] +
                                  (y * y)[:, np.newaxis], r * r) / (r * r)
                gain = 1 - 0.7 * rho2 + 0.35 * rho2 * rho2
                raw[:, lens * LENS_W:(lens + 1) * LENS_W] *= gain[..., None]
            raw = np.round(raw).astype(np.uint8)
            save(self.path("raw", f"f{seed}.png"), raw)
            raws.append(raw)
            flats.append(flat)
        circles = ["--circles", circles_arg(CIRCLES)]
        self.split(*circles, output=self.path("plain"))
        for seed, raw in enumerate(raws):
            self.assert_split(self.path("plain"), f"f{seed}.png", raw, CIRCLES)
        result = self.split(*circles, "--flat_field", "1",
                            output=self.path("flat"))
        for lens in ("lens0", "lens1"):
            self.assertRegex(result.stdout,
                             lens + r": light fall-off from 12 images, the rim "
                             r"at (6[0-9]|7[0-2])% of the centre")
        for lens, circle in enumerate(CIRCLES):
            inside = inside_mask(LENS_W, LENS_H, circle)
            cx, cy, r = circle
            x = np.arange(LENS_W) + 0.5 - cx
            y = np.arange(LENS_H) + 0.5 - cy
            rho = np.sqrt((x * x)[np.newaxis, :] + (y * y)[:, np.newaxis]) / r
            ring = inside & (rho > 0.75) & (rho < 0.95)
            for seed, flat in enumerate(flats):
                image = load(self.path("flat", "images", f"lens{lens}",
                                       f"f{seed}.png")).astype(np.float64)
                truth = flat[:, lens * LENS_W:(lens + 1) * LENS_W]
                darkened = raws[seed][:, lens * LENS_W:(lens + 1) * LENS_W]
                # Near the rim the corrected images are the undarkened ones
                # within a few per cent (the darkened ones 25-45% below).
                ratio = image[ring].sum() / truth[ring].sum()
                self.assertLess(abs(ratio - 1), 0.06, (lens, seed, ratio))
                self.assertLess(darkened[ring].sum() / truth[ring].sum(), 0.8)
                self.assertEqual(int(image[~inside].max()), 0)

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

        # Absurd circles: a centre outside the lens image, a circle that
        # covers a few percent of it.
        off_image = [CIRCLES[0], (120.0, 44.0, 30.0)]
        self.assert_refused(["lens1", "(cx, cy, r) = (120, 44, 30)",
                             "its centre is outside the 96x88 lens image"],
                            "--circles", circles_arg(off_image))
        tiny = [(48.0, 44.0, 10.0), CIRCLES[1]]
        self.assert_refused(["lens0", "covers 3.7% of the 96x88 lens image"],
                            "--circles", circles_arg(tiny))
        self.assert_refused(["--circles", "expected two circles"],
                            "--circles", "1,2,3")

        # An unreadable image, among good ones.
        with open(self.path("raw", "broken.png"), "wb") as f:
            f.write(b"\x89PNG\r\n\x1a\nnot really")
        self.assert_refused(["broken.png", "cannot read"], *given)
        os.remove(self.path("raw", "broken.png"))
        # A frame cut short (an interrupted copy), which OpenCV decodes
        # with gray where its data is missing.
        with open(self.path("raw", "good.png"), "rb") as f:
            data = f.read()
        with open(self.path("raw", "cut.png"), "wb") as f:
            f.write(data[:len(data) // 2])
        self.assert_refused(["cut.png", "truncated PNG: the file ends before"],
                            *given)
        os.remove(self.path("raw", "cut.png"))

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
        # A camera that is no lens for the 96x88 lens images: a focal length
        # of 0, a principal point a thousand images away.
        self.assert_refused(["--camera_params", "fx=0 must be positive",
                             "96x88 lens images"], *given,
                            "--camera_model", "OPENCV_FISHEYE",
                            "--camera_params", "0,40,48,44,0,0,0,0")
        self.assert_refused(["--camera_params", "principal point",
                             "96x88 lens images"], *given,
                            "--camera_model", "OPENCV_FISHEYE",
                            "--camera_params", "40,40,96000,44,0,0,0,0")
        self.assert_refused(["--circles", "radius of lens 1"],
                            "--circles", "48,44,40;48,44,0")

        # Only good.png is left: it splits.
        self.split(*given)
        self.assert_split(self.path("out"), "good.png", good, CIRCLES)


    def test_cropped_circles(self):
        """Circles reaching past the image's edges (real cameras crop them;
        refused before): given or detected, the mask is their part inside
        the lens image."""
        cropped = [(47.0, 44.0, 50.0), (50.5, 43.0, 52.0)]
        raws = {f"c{i}.png": make_raw(40 + i, circles=cropped)
                for i in range(3)}
        for name, raw in raws.items():
            save(self.path("raw", name), raw)
        for how, options in (("given", ["--circles", circles_arg(cropped)]),
                             ("detected", [])):
            with self.subTest(how):
                output = self.path("out_" + how)
                self.split(*options, output=output)
                circles = self.read_circles(output)
                got = [circles["lens0"], circles["lens1"]]
                for lens in range(2):
                    for value, true in zip(got[lens], cropped[lens]):
                        self.assertLess(abs(value - true), 1.0,
                                        (how, lens, got[lens]))
                    inside = inside_mask(LENS_W, LENS_H, got[lens])
                    # Cropped: fewer pixels than the whole disc.
                    self.assertLess(inside.sum(),
                                    np.pi * got[lens][2] ** 2 - 200)
                for name, raw in raws.items():
                    self.assert_split(output, name, raw, got)

    def write_lens_files(self, folder, names, raws, lens):
        for name, raw in zip(names, raws):
            save(self.path(folder, name),
                 np.ascontiguousarray(raw[:, lens * LENS_W:(lens + 1) * LENS_W]))

    def test_front_and_back_folders(self):
        """One file per lens (GoPro Fusion: FR/GPFR0001.png and
        BK/GPBK0001.png): the lens tag is found from the names; the frame
        is named without it."""
        raws = [make_raw(50 + i) for i in range(3)]
        self.write_lens_files("FR", [f"GPFR000{i}.png" for i in range(3)],
                              raws, 0)
        self.write_lens_files("BK", [f"GPBK000{i}.png" for i in range(3)],
                              raws, 1)
        output = self.path("out")
        result = self.split_folders("FR", "BK", output,
                                    "--circles", circles_arg(CIRCLES))
        self.assertIn('"FR" (front) and "BK" (back)', result.stdout)
        self.assertIn("3 raw frames -> 6 lens images", result.stdout)
        for i, raw in enumerate(raws):
            self.assert_split(output, f"GP000{i}.png", raw, CIRCLES)
        self.assertEqual(sorted(os.listdir(os.path.join(output, "images",
                                                        "lens1"))),
                         ["GP0000.png", "GP0001.png", "GP0002.png"])

        # Detected circles from the separate files, the same names in both
        # folders (no tag).
        self.write_lens_files("front", ["a.png", "b.png"], raws[:2], 0)
        self.write_lens_files("back", ["a.png", "b.png"], raws[:2], 1)
        output = self.path("out_same")
        self.split_folders("front", "back", output)
        circles = self.read_circles(output)
        detected = [circles["lens0"], circles["lens1"]]
        for got, true in zip(detected, CIRCLES):
            for value, expected in zip(got, true):
                self.assertLess(abs(value - expected), 1.0, (got, true))
        for name, raw in zip(("a.png", "b.png"), raws):
            self.assert_split(output, name, raw, detected)

        # A frame without its back file is named; nothing is written. With
        # --allow_incomplete_frames 1 its front lens is written alone.
        self.write_lens_files("FR", ["GPFR0003.png"], [make_raw(54)], 0)
        refused = self.path("refused")
        result = self.split_folders("FR", "BK", refused,
                                    "--circles", circles_arg(CIRCLES),
                                    check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("frame GP0003.png", result.stdout)
        self.assertIn("no file of the back lens", result.stdout)
        self.assertIn("--allow_incomplete_frames", result.stdout)
        self.assertFalse(os.path.exists(refused))
        output = self.path("out_incomplete")
        result = self.split_folders("FR", "BK", output,
                                    "--circles", circles_arg(CIRCLES),
                                    "--allow_incomplete_frames", "1")
        self.assertIn("4 raw frames -> 7 lens images", result.stdout)
        self.assertTrue(os.path.exists(os.path.join(
            output, "images", "lens0", "GP0003.png")))
        self.assertFalse(os.path.exists(os.path.join(
            output, "images", "lens1", "GP0003.png")))

        # A normal photo's halves as lens files are refused, named.
        rng = np.random.default_rng(55)
        photo = rng.integers(20, 256, size=raws[0].shape, dtype=np.uint8)
        self.write_lens_files("pFR", ["x.png"], [photo], 0)
        self.write_lens_files("pBK", ["x.png"], [photo], 1)
        result = self.split_folders("pFR", "pBK", refused,
                                    "--circles", circles_arg(CIRCLES),
                                    check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("x.png: lens 0: only", result.stdout)
        self.assertIn("not a dual-fisheye frame", result.stdout)
        self.assertFalse(os.path.exists(refused))

    def test_lens_suffixes(self):
        """One folder, NAME_0.png and NAME_1.png: frame NAME.png."""
        raws = [make_raw(60 + i) for i in range(2)]
        for i, raw in enumerate(raws):
            for lens in range(2):
                save(self.path("raw", f"IMG_{i}_{lens}.png"),
                     np.ascontiguousarray(
                         raw[:, lens * LENS_W:(lens + 1) * LENS_W]))
        output = self.path("out")
        self.split("--lens_suffixes", "_0,_1", "--circles",
                   circles_arg(CIRCLES))
        for i, raw in enumerate(raws):
            self.assert_split(output, f"IMG_{i}.png", raw, CIRCLES)
        save(self.path("raw", "IMG_9_2.png"), raws[0][:, :LENS_W])
        self.assert_refused(["IMG_9_2.png", "neither \"_0\" nor \"_1\""],
                            "--lens_suffixes", "_0,_1")
        self.assert_refused(["--lens_suffixes"], "--lens_suffixes", "_0")


REAL = os.path.join(SHARED_DATA, "real_cameras")


def read_maker_circles(path):
    """The (cx, cy, r) of each lens (front, back) of a GoPro parameter file:
    RADIUS: r and CENTER: cx cy lines, in lens image pixels."""
    with open(path) as f:
        text = f.read()
    radii = [float(v) for v in re.findall(r"RADIUS:\s*([\d.]+)", text)]
    centres = re.findall(r"CENTER:\s*([\d.]+)\s+([\d.]+)", text)
    return [(float(cx), float(cy), r) for (cx, cy), r in zip(centres, radii)]


@unittest.skipUnless(os.path.isdir(REAL),
                     f"needs {REAL} (the shared data set beside the "
                     "repository); not available here")
class RealGoProFusionTest(TempDirTestCase):
    """The GoPro Fusion's own files (one per lens, FR/ and BK/; circles
    cropped by the frame's top and bottom, a lens housing and flare around
    them): every frame split, with the maker's circles and with detected
    ones; its maker's stitched panoramas refused."""

    read_circles = DualFisheyeSplitterTest.read_circles

    def link_pairs(self, camera, count):
        """Folders FR and BK in the temporary folder linking to the first
        COUNT files of CAMERA's (once); their names."""
        names = {}
        for folder in ("FR", "BK"):
            source = os.path.join(REAL, camera, folder)
            names[folder] = sorted(os.listdir(source))[:count]
            if os.path.isdir(self.path(camera, folder)):
                continue
            os.makedirs(self.path(camera, folder))
            for name in names[folder]:
                os.symlink(os.path.join(source, name),
                           self.path(camera, folder, name))
        return names

    def frame_name(self, front_name, back_name):
        """The name both lenses' files share: the front name without the
        characters where the two differ (the lens tag)."""
        prefix = len(os.path.commonprefix([front_name, back_name]))
        suffix = len(os.path.commonprefix([front_name[::-1],
                                           back_name[::-1]]))
        return front_name[:prefix] + front_name[len(front_name) - suffix:]

    def split_and_check(self, camera, count, circles, max_offset):
        names = self.link_pairs(camera, count)
        output = self.path(camera + ("_given" if circles else "_detected"))
        options = ["--circles", circles_arg(circles)] if circles else []
        start = time.time()
        result = run_colmap("dual_fisheye_splitter",
                            "--front_path", self.path(camera, "FR"),
                            "--back_path", self.path(camera, "BK"),
                            "--output_path", output, *options)
        seconds = time.time() - start
        maker = read_maker_circles(os.path.join(REAL, camera, "circles.txt"))
        written = self.read_circles(output)
        used = [written["lens0"], written["lens1"]]
        if circles:
            self.assertEqual(used, [tuple(c) for c in circles])
        for lens in range(2):
            offset = max(abs(a - b) for a, b in zip(used[lens], maker[lens]))
            print(f"{camera} {'given' if circles else 'detected'} lens{lens}: "
                  f"{used[lens]} vs the maker's {maker[lens]}: "
                  f"{offset:.1f} px; {seconds:.1f} s")
            self.assertLessEqual(offset, max_offset, (lens, used, maker))
        self.assertIn(f"{count} raw frames -> {2 * count} lens images",
                      result.stdout)
        for front, back in zip(names["FR"], names["BK"]):
            name = self.frame_name(front, back)
            for lens, lens_name, source in ((0, "lens0", front),
                                            (1, "lens1", back)):
                with Image.open(os.path.join(REAL, camera,
                                             ("FR", "BK")[lens],
                                             source)) as original:
                    width, height = original.size
                image = load(os.path.join(output, "images", lens_name, name))
                self.assertEqual(image.shape[:2], (height, width), name)
                mask = load(os.path.join(output, "masks", lens_name,
                                         name + ".png"))
                inside = inside_mask(width, height, used[lens])
                # The circle reaches past the top and bottom: the mask is
                # its part inside the image, pixel for pixel.
                self.assertGreater(used[lens][2] * 2, height)
                np.testing.assert_array_equal(mask, np.where(inside, 255, 0),
                                              err_msg=f"{lens_name}/{name}")
                # Outside the circle black (JPEG leaves a little ringing at
                # the rim).
                self.assertLess(float(image[~inside].mean()), 2.0, name)
                self.assertGreater(float(image[inside].mean()), 20.0, name)
        return result.stdout

    def test_3k_video_frames(self):
        maker = read_maker_circles(os.path.join(REAL, "gopro_fusion_3k",
                                                "circles.txt"))
        self.split_and_check("gopro_fusion_3k", 5, maker, 0)
        # Detected: the picture's edge is soft (vignetting, blooming next to
        # a bright sky), and the front lens's circle moves by ~13 px between
        # the first two and the last three frames: within 1.5% of r of the
        # maker's circle.
        log = self.split_and_check("gopro_fusion_3k", 5, None, 0.015 * 765)
        self.assertIn("lens0's image circle differs between frames", log)
        self.assertNotIn("lens1's image circle differs", log)

    def test_18mp_photo(self):
        maker = read_maker_circles(os.path.join(REAL, "gopro_fusion_photo",
                                                "circles.txt"))
        self.split_and_check("gopro_fusion_photo", 1, maker, 0)
        # The maker's front circle lies ~20 px inside the picture's edge at
        # the bottom and the sides: within 1.5% of r.
        self.split_and_check("gopro_fusion_photo", 1, None, 0.015 * 1520)

    def test_stitched_panorama_is_refused(self):
        source = os.path.join(REAL, "gopro_fusion_3k", "STITCHED")
        name = sorted(os.listdir(source))[0]
        os.makedirs(self.path("stitched"))
        os.symlink(os.path.join(source, name), self.path("stitched", name))
        maker = read_maker_circles(os.path.join(REAL, "gopro_fusion_3k",
                                                "circles.txt"))
        for options, needle in ((["--circles", circles_arg(maker)],
                                 "not a dual-fisheye frame"),
                                ([], "no image circle")):
            output = self.path("refused")
            result = run_colmap("dual_fisheye_splitter", "--input_path",
                                self.path("stitched"), "--output_path",
                                output, *options, check=False)
            self.assertNotEqual(result.returncode, 0)
            self.assertIn(name, result.stdout)
            self.assertIn(needle, result.stdout)
            self.assertFalse(os.path.exists(output))


if __name__ == "__main__":
    unittest.main()
