"""Damaged model files: every reading command reports the damaged file in a
one-line error and exits with 1; no abort, no signal, no hang, the input
untouched and nothing written.

The corpus is made here from a small valid model (two cameras, four images,
points with tracks). Binary: each of its five files (rigs, cameras, frames,
images, points3D) truncated at nine places and to nothing, its leading count
raised by one and set to 2^62 (a size that must not be allocated), and
replaced by random bytes of the same size. Text: each file cut inside a
line at five places, without its last line, with a value that is not a
number and one that is not finite. Binary: a camera parameter and a point
coordinate set to NaN and to infinity. Each case runs through
`model_analyzer` and `model_converter`; non-finite values in text and binary
files also through the evaluator, the bundle adjuster and both
undistorters.
"""
import hashlib
import os
import random
import shutil
import struct
import subprocess

from cli_util import TempDirTestCase
from sphera_common import COLMAP, run_colmap

import unittest

MODEL_FILES = ("rigs", "cameras", "frames", "images", "points3D")
COMMANDS = ("model_analyzer", "model_converter")
TIMEOUT_S = 180  # a hang, not a slow run: each command takes about a second


def write_valid_text_model(path):
    """A small consistent model in text format at PATH."""
    os.makedirs(path)
    with open(os.path.join(path, "cameras.txt"), "w") as f:
        f.write("1 PINHOLE 640 480 500 510 320 240\n")
        f.write("2 EQUIRECTANGULAR 2048 1024 2048 1024\n")
    rng = random.Random(5)
    points = {}
    observations = {image_id: [] for image_id in range(1, 5)}
    for point_id in range(1, 41):
        track = []
        for image_id in rng.sample(range(1, 5), 2 + point_id % 3):
            track.append((image_id, len(observations[image_id])))
            observations[image_id].append(
                (rng.uniform(10, 600), rng.uniform(10, 460), point_id))
        points[point_id] = ((rng.uniform(-1, 1), rng.uniform(-1, 1),
                             rng.uniform(3, 5)), track)
    with open(os.path.join(path, "images.txt"), "w") as f:
        for image_id in range(1, 5):
            camera_id = 1 if image_id <= 2 else 2
            f.write(f"{image_id} 1 0 0 0 {0.3 * image_id} 0 0 {camera_id} "
                    f"image{image_id}.jpg\n")
            f.write(" ".join(f"{x} {y} {p}"
                             for x, y, p in observations[image_id]) + "\n")
    with open(os.path.join(path, "points3D.txt"), "w") as f:
        for point_id, (xyz, track) in points.items():
            f.write(f"{point_id} {xyz[0]} {xyz[1]} {xyz[2]} 128 128 128 0.5 "
                    + " ".join(f"{i} {j}" for i, j in track) + "\n")


def binary_damages(data):
    """[(label, damaged bytes)] of the binary model file DATA."""
    damages = [("truncated to 0", b"")]
    for k in range(1, 10):
        cut = len(data) * k // 10
        damages.append((f"truncated at {cut}/{len(data)}", data[:cut]))
    count = struct.unpack("<Q", data[:8])[0]
    damages.append(("count + 1", struct.pack("<Q", count + 1) + data[8:]))
    damages.append(("count 2^62", struct.pack("<Q", 1 << 62) + data[8:]))
    rng = random.Random(17)
    damages.append(("random bytes", bytes(rng.getrandbits(8) for _ in data)))
    return damages


def text_damages(data):
    """[(label, damaged bytes)] of the text model file DATA: cut inside a
    line at five places, without its last data line, and its first data
    line with a value that is not a number and one that is not finite."""
    lines = data.split(b"\n")
    data_lines = [i for i, line in enumerate(lines)
                  if line and not line.startswith(b"#")]
    first, last = data_lines[0], data_lines[-1]
    header = len(b"\n".join(lines[:first])) + 1
    damages = []
    for k in range(1, 6):
        cut = header + (len(data) - header) * k // 6
        while data[cut - 1:cut] in (b"\n", b" "):
            cut -= 1
        damages.append((f"cut inside a line at {cut}/{len(data)}",
                        data[:cut]))
    damages.append(("its last data line removed",
                    b"\n".join(lines[:last] + lines[last + 1:])))
    for label, value in (("not a number", b"abc"), ("not finite", b"nan")):
        tokens = lines[first].split(b" ")
        tokens[2] = value
        damages.append((f"{label} in line {first + 1}", b"\n".join(
            lines[:first] + [b" ".join(tokens)] + lines[first + 1:])))
    return damages


def damaged_models(valid, extension, damages):
    """[(case name, damaged file name, {file name: bytes})]: the model VALID
    ({file name: bytes}) with one of its files (STEM + EXTENSION) replaced
    by each of DAMAGES(its bytes)."""
    cases = []
    for stem in MODEL_FILES:
        name = stem + extension
        for label, damaged in damages(valid[name]):
            files = dict(valid)
            files[name] = damaged
            cases.append((f"{name} {label}", name, files))
    return cases


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


class BadModelTest(TempDirTestCase):
    def setUp(self):
        super().setUp()
        write_valid_text_model(self.path("text"))
        os.makedirs(self.path("binary"))
        run_colmap("model_converter", "--input_path", self.path("text"),
                   "--output_path", self.path("binary"), "--output_type",
                   "BIN")
        # The text model as COLMAP writes it, with rigs and frames.
        os.makedirs(self.path("text_full"))
        run_colmap("model_converter", "--input_path", self.path("binary"),
                   "--output_path", self.path("text_full"), "--output_type",
                   "TXT")
        self.valid = {}
        self.valid_text = {}
        for stem in MODEL_FILES:
            with open(self.path("binary", stem + ".bin"), "rb") as f:
                self.valid[stem + ".bin"] = f.read()
            with open(self.path("text_full", stem + ".txt"), "rb") as f:
                self.valid_text[stem + ".txt"] = f.read()

    def run_command(self, command, model, output):
        if command == "model_analyzer":
            args = ["model_analyzer", "--path", model]
        elif command == "model_converter":
            args = ["model_converter", "--input_path", model, "--output_path",
                    output, "--output_type", "TXT"]
        elif command == "model_evaluator (input)":
            args = ["model_evaluator", "--gt_path", self.path("binary"),
                    "--input_path", model, "--output_path", output]
        elif command == "model_evaluator (ground truth)":
            args = ["model_evaluator", "--gt_path", model, "--input_path",
                    self.path("binary"), "--output_path", output]
        elif command == "bundle_adjuster":
            args = ["bundle_adjuster", "--input_path", model, "--output_path",
                    output]
        else:  # the undistorters
            args = [command, "--input_path", model, "--image_path",
                    self.path("images"), "--output_path", output]
        try:
            result = subprocess.run([COLMAP, *args], stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, text=True,
                                    errors="replace", timeout=TIMEOUT_S)
        except subprocess.TimeoutExpired:
            return None, f"no exit within {TIMEOUT_S} s"
        return result.returncode, result.stdout

    def test_valid_model_reads(self):
        for command in COMMANDS:
            os.makedirs(self.path("out_valid_" + command))
            code, output = self.run_command(command, self.path("binary"),
                                            self.path("out_valid_" + command))
            self.assertEqual(code, 0, output[-2000:])

    def check_named_errors(self, cases, commands=COMMANDS):
        """Runs every command of COMMANDS on every damaged model of CASES
        and checks the outcome; returns the number of runs."""
        runs = 0
        for index, (case, damaged_name, files) in enumerate(cases):
            model = self.path(f"case{index}")
            os.makedirs(model)
            for name, data in files.items():
                with open(os.path.join(model, name), "wb") as f:
                    f.write(data)
            before = {name: digest(os.path.join(model, name))
                      for name in files}
            for command in commands:
                output_dir = self.path(f"out{index}_{command}")
                os.makedirs(output_dir)
                with self.subTest(case=case, command=command):
                    code, output = self.run_command(command, model,
                                                    output_dir)
                    tail = output[-1500:]
                    runs += 1
                    self.assertEqual(code, 1, f"{case}: exit {code}\n{tail}")
                    # The damaged file, or the file that refers to what
                    # the damage removed (frames.txt to a rig of a cut
                    # rigs.txt).
                    self.assertTrue(
                        any(os.path.join(model, name) in output
                            for name in files), tail)
                    if damaged_name.endswith(".bin"):
                        self.assertIn(damaged_name, output, tail)
                    for marker in ("terminate called", "SIGSEGV", "SIGABRT",
                                   "Aborted"):
                        self.assertNotIn(marker, output, tail)
                    self.assertEqual(os.listdir(output_dir), [],
                                     "something was written")
            after = {name: digest(os.path.join(model, name))
                     for name in files}
            self.assertEqual(before, after, f"{case}: the input changed")
            shutil.rmtree(model)
        return runs

    def test_damaged_binary_files_are_named_errors(self):
        cases = damaged_models(self.valid, ".bin", binary_damages)
        self.assertEqual(len(cases), 5 * 13)
        runs = self.check_named_errors(cases)
        self.assertEqual(runs, 5 * 13 * len(COMMANDS))
        print(f"{runs} runs on damaged binary models, all named errors")

    def test_damaged_text_files_are_named_errors(self):
        cases = damaged_models(self.valid_text, ".txt", text_damages)
        self.assertEqual(len(cases), 5 * 8)
        runs = self.check_named_errors(cases)
        self.assertEqual(runs, 5 * 8 * len(COMMANDS))
        print(f"{runs} runs on damaged text models, all named errors")

    def test_non_finite_binary_values_are_named_errors(self):
        # cameras.bin: count (8 bytes), camera_id (4), model (4), width (8),
        # height (8), then the parameters; points3D.bin: count (8),
        # point3D_id (8), then x, y, z.
        nan, inf = struct.pack("<d", float("nan")), struct.pack("<d", float("inf"))
        cases = []
        for name, offset, value in (("cameras.bin", 32, nan),
                                    ("cameras.bin", 40, inf),
                                    ("points3D.bin", 16, nan),
                                    ("points3D.bin", 32, inf)):
            data = self.valid[name]
            files = dict(self.valid)
            files[name] = data[:offset] + value + data[offset + 8:]
            cases.append((f"{name} not finite at {offset}", name, files))
        runs = self.check_named_errors(cases)
        self.assertEqual(runs, 4 * len(COMMANDS))

    def test_non_finite_values_stop_every_command_that_reads_models(self):
        """NaN and infinity in a camera, a pose or a point, in text and in
        binary files, are refused where they enter: by every command that
        reads a model (the evaluator on either side, the bundle adjuster,
        both undistorters), not written into their outputs."""
        os.makedirs(self.path("images"))
        nan = struct.pack("<d", float("nan"))
        cases = []
        # Binary: a camera parameter, a point coordinate, an image's
        # quaternion (images.bin: count (8), image_id (4), then qw; unused
        # when frames.bin holds the poses) and a frame's translation
        # (frames.bin: count (8), frame_id (4), rig_id (4), qw qx qy qz, tx).
        for name, offset in (("cameras.bin", 32), ("points3D.bin", 16),
                             ("images.bin", 12), ("frames.bin", 48)):
            data = self.valid[name]
            files = dict(self.valid)
            files[name] = data[:offset] + nan + data[offset + 8:]
            cases.append((f"{name} NaN at {offset}", name, files))
        # Text: in the first data line of each file, the first camera
        # parameter, an image's qx or a point's y set to inf.
        for stem in ("cameras", "images", "points3D"):
            name = stem + ".txt"
            lines = self.valid_text[name].split(b"\n")
            first = next(i for i, line in enumerate(lines)
                         if line and not line.startswith(b"#"))
            tokens = lines[first].split(b" ")
            tokens[4 if stem == "cameras" else 2] = b"inf"
            files = dict(self.valid_text)
            files[name] = b"\n".join(lines[:first] + [b" ".join(tokens)] +
                                     lines[first + 1:])
            cases.append((f"{name} inf in line {first + 1}", name, files))
        commands = ("model_evaluator (input)", "model_evaluator (ground truth)",
                    "bundle_adjuster", "image_undistorter",
                    "sphere_undistorter")
        runs = self.check_named_errors(cases, commands)
        self.assertEqual(runs, 7 * len(commands))
        print(f"{runs} runs of model-reading commands on non-finite values, "
              "all named errors")


if __name__ == "__main__":
    unittest.main()
