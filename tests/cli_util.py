"""Helpers for the integration tests that drive the built `colmap` program."""
import os
import random
import re
import shutil
import sqlite3
import struct
import subprocess
import sys
import tempfile
import unittest

COLMAP = os.environ.get("SPHERA_COLMAP", "")
SHARED_DATA = os.environ.get(
    "SPHERA_SHARED_DATA",
    os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data"))

# ctest reports a test that exits with this code as skipped.
SKIP_EXIT_CODE = 77

# Prefixes of COLMAP's feature extraction and matching options
# (--FeatureExtraction.*, --FeatureMatching.*).
EXTRACTION = "FeatureExtraction"
MATCHING = "FeatureMatching"
# Feature extraction and matching on the CPU.
CPU_EXTRACTION = [f"--{EXTRACTION}.use_gpu", "0"]
CPU_MATCHING = [f"--{MATCHING}.use_gpu", "0"]


def run_colmap(*args, check=True, timeout=1800):
    """Runs `colmap ARGS`, returns the CompletedProcess (stdout+stderr text)."""
    if not COLMAP or not os.path.exists(COLMAP):
        raise RuntimeError(f"SPHERA_COLMAP={COLMAP!r} is not the built colmap")
    result = subprocess.run([COLMAP, *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True,
                            timeout=timeout)
    if check and result.returncode != 0:
        raise AssertionError(f"colmap {' '.join(map(str, args))} exited "
                             f"{result.returncode}:\n{result.stdout[-4000:]}")
    return result


def analyze_model(model_path):
    """(registered images, points, mean reprojection error in px) that
    `colmap model_analyzer` reports for a model."""
    analysis = run_colmap("model_analyzer", "--path", model_path).stdout
    registered = int(re.search(r"Registered images: (\d+)", analysis)[1])
    points = int(re.search(r"Points: (\d+)", analysis)[1])
    reprojection_px = float(
        re.search(r"Mean reprojection error: ([0-9.]+)px", analysis)[1])
    return registered, points, reprojection_px


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


def read_text_cameras(path):
    """{camera_id: (model name, width, height, [params])} of PATH/cameras.txt."""
    cameras = {}
    with open(os.path.join(path, "cameras.txt")) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            fields = line.split()
            cameras[int(fields[0])] = (fields[1], int(fields[2]),
                                       int(fields[3]),
                                       [float(v) for v in fields[4:]])
    return cameras


def read_text_model(path):
    """(cameras {id: (model, width, height, params)},
        images {id: (header fields, [(x, y, point3D_id)])},
        points {id: ((x, y, z), [(image_id, point2D_idx)])})."""
    cameras = read_text_cameras(path)
    images = {}
    with open(os.path.join(path, "images.txt")) as f:
        lines = [l.rstrip("\n") for l in f if not l.startswith("#")]
    for header, points in zip(lines[0::2], lines[1::2]):
        fields = header.split()
        values = points.split()
        observations = [(float(values[i]), float(values[i + 1]),
                         int(values[i + 2]))
                        for i in range(0, len(values), 3)]
        images[int(fields[0])] = (fields, observations)
    points = {}
    with open(os.path.join(path, "points3D.txt")) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            fields = line.split()
            track = [(int(fields[i]), int(fields[i + 1]))
                     for i in range(8, len(fields), 2)]
            points[int(fields[0])] = (tuple(float(v) for v in fields[1:4]),
                                      track)
    return cameras, images, points


def rotation_from_quaternion(qw, qx, qy, qz):
    """Rotation matrix (numpy) of a unit quaternion (w, x, y, z)."""
    import numpy as np
    w, x, y, z = qw, qx, qy, qz
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def text_model_poses(path):
    """{image name: (R cam_from_world, camera centre)} of a text model."""
    import numpy as np
    _, images, _ = read_text_model(path)
    poses = {}
    for fields, _ in images.values():
        rotation = rotation_from_quaternion(*map(float, fields[1:5]))
        translation = np.array([float(v) for v in fields[5:8]])
        poses[fields[9]] = (rotation, -rotation.T @ translation)
    return poses


def pose_errors(gt_path, model_path):
    """Aligns the text model at MODEL_PATH to the one at GT_PATH by the
    least-squares similarity of the camera centres (Umeyama 1991) and returns
    {image name: (rotation error in degrees, position error)} for the images
    of both: ||log(R_gt R_est^T)|| and the distance of the centres."""
    import numpy as np
    gt = text_model_poses(gt_path)
    est = text_model_poses(model_path)
    names = sorted(set(gt) & set(est))
    gt_centres = np.array([gt[n][1] for n in names])
    est_centres = np.array([est[n][1] for n in names])
    gt_mean, est_mean = gt_centres.mean(0), est_centres.mean(0)
    gt_d, est_d = gt_centres - gt_mean, est_centres - est_mean
    u, singular, vt = np.linalg.svd(gt_d.T @ est_d / len(names))
    sign = np.eye(3)
    if np.linalg.det(u @ vt) < 0:
        sign[2, 2] = -1
    gt_from_est = u @ sign @ vt
    scale = np.trace(np.diag(singular) @ sign) / (est_d ** 2).sum(1).mean()
    errors = {}
    for name in names:
        centre = scale * gt_from_est @ (est[name][1] - est_mean) + gt_mean
        # est cam_from_world composed with est_from_gt maps gt world to cam.
        relative = gt[name][0] @ (est[name][0] @ gt_from_est.T).T
        angle = np.arccos(np.clip((np.trace(relative) - 1) / 2, -1, 1))
        errors[name] = (np.degrees(angle),
                        float(np.linalg.norm(centre - gt[name][1])))
    return errors


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
