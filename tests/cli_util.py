"""Helpers for the integration tests that drive the built `colmap` program:
test cases, fixtures and the skip protocol. What the benchmark scripts use
too (models, rotations, running colmap and sphera_render) is in
scripts/sphera_common.py."""
import os
import random
import resource
import shutil
import sqlite3
import struct
import subprocess
import sys
import tempfile
import time
import unittest

from sphera_common import RENDER, SHARED_DATA_DIR

SHARED_DATA = os.environ.get("SPHERA_SHARED_DATA", SHARED_DATA_DIR)

# ctest reports a test that exits with this code as skipped.
SKIP_EXIT_CODE = 77


def _timed_run(run):
    """subprocess.run that appends a line to the file SPHERA_TEST_TIMES for
    every program it runs: seconds of wall time and of CPU time (user and
    system, all threads), the test method that ran it, the program and its
    first argument (colmap's command)."""
    def timed(args, *rest, **options):
        start = time.monotonic()
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        try:
            return run(args, *rest, **options)
        finally:
            seconds = time.monotonic() - start
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = (after.ru_utime + after.ru_stime - before.ru_utime -
                   before.ru_stime)
            frame, caller = sys._getframe(1), "-"
            while frame is not None:
                if isinstance(frame.f_locals.get("self"), unittest.TestCase):
                    caller = frame.f_locals["self"].id()
                    break
                frame = frame.f_back
            if frame is None:
                frame = sys._getframe(1)
                while frame.f_back is not None and frame.f_code.co_name in (
                        "run_program", "run_colmap", "run_render",
                        "extract_features", "match_exhaustive"):
                    frame = frame.f_back
                caller = frame.f_code.co_name
            words = [str(a) for a in (args if isinstance(args, (list, tuple))
                                      else [args])]
            program = os.path.basename(words[0])
            with open(os.environ["SPHERA_TEST_TIMES"], "a") as log:
                log.write(f"{seconds:8.2f} {cpu:8.2f} {caller} {program} "
                          f"{words[1] if len(words) > 1 else ''}\n")
    return timed


# Profiling: SPHERA_TEST_TIMES=FILE logs the wall and CPU seconds of every
# program a test runs (colmap, sphera_render) to FILE.
if os.environ.get("SPHERA_TEST_TIMES"):
    subprocess.run = _timed_run(subprocess.run)


def write_noise_image(path, width, height, seed, gray=True):
    """Writes a binary PGM with multi-scale blob texture that SIFT can match."""
    rng = random.Random(seed)
    pixels = bytearray(width * height)
    # Value noise on a few scales, summed; nearest-cell lookups are enough to
    # give SIFT corners and blobs.
    layers = []
    for cell in (64, 24, 9):
        cols, rows = width // cell + 2, height // cell + 2
        layers.append((cell, cols, [rng.random() for _ in range(cols * rows)]))
    for y in range(height):
        for x in range(width):
            value = 0.0
            for cell, cols, grid in layers:
                value += grid[(y // cell) * cols + x // cell]
            pixels[y * width + x] = min(255, int(value / len(layers) * 255))
    with open(path, "wb") as f:
        f.write(f"P5\n{width} {height}\n255\n".encode())
        f.write(bytes(pixels))


def listing(root):
    """{relative path: size in bytes (-1 for a folder)} of everything below
    ROOT: what a failed command must not have written or changed."""
    result = {}
    for folder, dirs, files in os.walk(root):
        for name in dirs + files:
            path = os.path.join(folder, name)
            result[os.path.relpath(path, root)] = (
                os.path.getsize(path) if os.path.isfile(path) else -1)
    return result


class Database:
    """Read-only view of a COLMAP database."""

    def __init__(self, path):
        self.connection = sqlite3.connect(f"file:{path}?mode=ro", uri=True)

    def close(self):
        self.connection.close()

    def scalar(self, sql, *args):
        return self.connection.execute(sql, args).fetchone()[0]

    def cameras(self):
        rows = self.connection.execute(
            "SELECT camera_id, model, width, height, params FROM cameras")
        cameras = {}
        for camera_id, model, width, height, params in rows:
            values = struct.unpack(f"{len(params) // 8}d", params)
            cameras[camera_id] = (model, width, height, list(values))
        return cameras

    def images(self):
        return dict(self.connection.execute(
            "SELECT name, camera_id FROM images").fetchall())

    def num_keypoints(self):
        return dict(self.connection.execute(
            "SELECT images.name, keypoints.rows FROM keypoints "
            "JOIN images ON images.image_id = keypoints.image_id").fetchall())


class TempDirTestCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="sphera_test_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def path(self, *parts):
        return os.path.join(self.tmp, *parts)


def main_with_skip(required_paths):
    """unittest.main(), but exits SKIP_EXIT_CODE when a data path is missing."""
    missing = [p for p in required_paths if not os.path.exists(p)]
    if missing:
        print(f"SKIP: needs {', '.join(missing)} (the shared data set beside "
              "the repository); not available here")
        sys.exit(SKIP_EXIT_CODE)
    unittest.main()


def main_with_render():
    """unittest.main(), but exits with a message when SPHERA_RENDER is not
    the built renderer."""
    require_render()
    unittest.main()


def require_render():
    """Exits with a message when SPHERA_RENDER is not the built renderer."""
    if not os.path.exists(RENDER):
        raise SystemExit(f"SPHERA_RENDER={RENDER!r} is not the built renderer")
