#!/usr/bin/python3
"""SfM benchmark of SPHERA (and stock COLMAP 3.10 where it applies).

Runs the COLMAP command-line pipeline (feature_extractor, exhaustive_matcher,
mapper) on each data set, evaluates the largest model against the ground
truth with `colmap model_evaluator`, and writes a table, a CSV and a PNG.

Usage (from the repository root):
  scripts/benchmark_sfm.py                      all data sets, SPHERA and stock
  scripts/benchmark_sfm.py --only room9_equirect,fountain-P11
  scripts/benchmark_sfm.py --quick --no_stock   smaller renders, SPHERA only
  scripts/benchmark_sfm.py --list               the data sets

Data sets (rows):
  room9_equirect     9 equirectangular 2048x1024 cameras, room9 layout (SPHERA)
  room_fisheye190    12 UNIFIED_OMNI 190-degree fisheye 1024x1024 (SPHERA)
  room_hybrid        4 equirect + 4 fisheye + 4 PINHOLE 800x600 (SPHERA)
  room_poles         9 equirectangular 2048x1024, alternately near floor and
                     ceiling: many features near the poles (SPHERA)
  room_pinhole_ring  16 PINHOLE 640x480, ring layout (SPHERA and stock)
  fountain-P11       Strecha, 11 perspective 3072x2048 (SPHERA and stock)
  entry-P10          Strecha, 10 perspective 3072x2048 (SPHERA and stock)
  equirect_flat      11 real Ricoh Theta 5376x2688, no ground truth (SPHERA)

Rendered scenes are cached in OUTPUT_DIR/scenes/<name> (OUTPUT_DIR/scenes/
<name>_quick with --quick) and reused; delete a directory to re-render it.
Each run works in OUTPUT_DIR/runs/<dataset>/<system>/ (database, sparse
models, evaluation.json, logs/ with every command's output). Results go to
OUTPUT_DIR/sfm_results.csv and OUTPUT_DIR/sfm_results.png; rows of earlier
runs that this run did not redo are kept in the CSV unless --fresh.

Stock COLMAP (build-stock/bin/colmap) is built with scripts/build_stock.sh
when missing (about 25 minutes), unless --no_stock. Stock runs only on the
perspective sets. Shared real data (../shared/data by default) may be absent:
those rows are reported as skipped. A failing data set is recorded in the
`status` column and does not stop the run.

Needs Debian's python3 (python3-matplotlib for the PNG; without it the PNG
is skipped with a note).
"""

import argparse
import csv
import datetime
import glob
import json
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

DATASETS = [
    "room9_equirect",
    "room_fisheye190",
    "room_hybrid",
    "room_poles",
    "room_pinhole_ring",
    "fountain-P11",
    "entry-P10",
    "equirect_flat",
]
# Perspective sets: stock COLMAP runs too, and the SPHERA row gets ratios.
STOCK_DATASETS = {"room_pinhole_ring", "fountain-P11", "entry-P10"}

COLUMNS = [
    "dataset", "system", "status", "registered", "total", "num_models",
    "points", "rot_err_mean_deg", "rot_err_max_deg", "pos_err_mean",
    "pos_err_max", "pos_err_mean_norm", "reproj_px", "point_err_mean",
    "point_err_median", "t_extract_s", "t_match_s", "t_map_s",
    "map_time_ratio", "rot_err_ratio", "render", "timestamp",
]

RENDER_SEED = 1
DEFAULT_STEP_TIMEOUT = 3 * 3600


# ---------------------------------------------------------------------------
# Small helpers


def log(message):
    print("[bench] " + message, flush=True)


def fmt(value, digits=3):
    """Formats a number for the table ('-' when missing)."""
    if value is None or value == "":
        return "-"
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            return value
    if isinstance(value, int) or (isinstance(value, float) and value.is_integer()
                                  and abs(value) >= 1000):
        return str(int(value))
    if value == 0:
        return "0"
    if abs(value) >= 100:
        return "%.0f" % value
    if abs(value) >= 1:
        return "%.*f" % (max(digits - 1, 1), value)
    return "%.*g" % (digits, value)


def to_float(value):
    if value is None or value == "":
        return None
    try:
        result = float(value)
    except (TypeError, ValueError):
        return None
    return result if math.isfinite(result) else None


def error_summary(text, limit=200):
    """The most informative line of a COLMAP log: the last glog error or
    fatal message, an exception's what(), or else the last line."""
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    patterns = [
        re.compile(r"what\(\):\s*(.*)"),
        re.compile(r"^[EF]\d{8} [\d:.]+\s+\d+\s+\S+\]\s*(.*)"),
        re.compile(r"^(?:ERROR|Error|error)[:\s]+(.*)"),
        re.compile(r"(.*(?:[Ee]rror|[Ff]ailed|cannot|only \d+ registered).*)"),
    ]
    for pattern in patterns:
        for line in reversed(lines):
            match = pattern.search(line)
            if match and match.group(1).strip():
                return match.group(1).strip()[:limit]
    return (lines[-1] if lines else "no output")[:limit]


class StepError(Exception):
    """A pipeline step failed; the message goes to the status column."""


def run_step(name, command, log_dir, timeout):
    """Runs `command`, logging to log_dir/name.log; returns (seconds, output).
    Raises StepError on a non-zero exit or timeout."""
    os.makedirs(log_dir, exist_ok=True)
    log_path = os.path.join(log_dir, name + ".log")
    env = dict(os.environ)
    env.setdefault("QT_QPA_PLATFORM", "offscreen")
    start = time.monotonic()
    with open(log_path, "w") as log_file:
        log_file.write("$ " + " ".join(command) + "\n")
        log_file.flush()
        try:
            process = subprocess.run(command, stdout=log_file,
                                     stderr=subprocess.STDOUT, env=env,
                                     timeout=timeout, cwd=REPO_ROOT)
        except subprocess.TimeoutExpired:
            raise StepError("%s timed out after %d s (log %s)" %
                            (name, timeout, log_path))
        except OSError as error:
            raise StepError("%s: cannot run %s: %s" % (name, command[0], error))
    seconds = time.monotonic() - start
    with open(log_path, errors="replace") as log_file:
        output = log_file.read()
    if process.returncode != 0:
        raise StepError("%s failed (exit %d): %s" %
                        (name, process.returncode, error_summary(output)))
    return seconds, output


def count_binary_model(model_dir):
    """(registered images, points) of a COLMAP binary (or text) model."""
    def binary_count(path):
        with open(path, "rb") as f:
            return struct.unpack("<Q", f.read(8))[0]

    def text_count(path, lines_per_item):
        count = 0
        with open(path) as f:
            for line in f:
                if line.strip() and not line.startswith("#"):
                    count += 1
        return count // lines_per_item

    images_bin = os.path.join(model_dir, "images.bin")
    if os.path.exists(images_bin):
        return (binary_count(images_bin),
                binary_count(os.path.join(model_dir, "points3D.bin")))
    images_txt = os.path.join(model_dir, "images.txt")
    if os.path.exists(images_txt):
        # Text images.txt: an empty POINTS2D line may be dropped by the
        # count; count header lines only.
        return (len(read_text_images(images_txt)),
                text_count(os.path.join(model_dir, "points3D.txt"), 1))
    return None


def sparse_models(sparse_dir):
    """Sub-model directories of a mapper output, largest first."""
    models = []
    for path in sorted(glob.glob(os.path.join(sparse_dir, "*"))):
        if not os.path.isdir(path):
            continue
        counts = count_binary_model(path)
        if counts is not None:
            models.append((counts[0], counts[1], path))
    models.sort(key=lambda m: (-m[0], -m[1]))
    return models


def jpeg_size(path):
    """(width, height) of a JPEG from its SOF marker."""
    with open(path, "rb") as f:
        if f.read(2) != b"\xff\xd8":
            raise ValueError("not a JPEG: " + path)
        while True:
            byte = f.read(1)
            while byte and byte != b"\xff":
                byte = f.read(1)
            while byte == b"\xff":
                byte = f.read(1)
            if not byte:
                raise ValueError("no SOF marker in " + path)
            marker = byte[0]
            if marker in (0xD8, 0x01) or 0xD0 <= marker <= 0xD7:
                continue
            (length,) = struct.unpack(">H", f.read(2))
            if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):
                _, height, width = struct.unpack(">BHH", f.read(5))
                return width, height
            f.seek(length - 2, 1)


IMAGE_EXTENSIONS = (".jpg", ".jpeg", ".png", ".tif", ".tiff", ".bmp")


def list_images(directory):
    """Image files directly in `directory`, sorted."""
    return sorted(n for n in os.listdir(directory)
                  if n.lower().endswith(IMAGE_EXTENSIONS)
                  and os.path.isfile(os.path.join(directory, n)))


def is_number(text):
    try:
        float(text)
        return True
    except ValueError:
        return False


def read_text_cameras(path):
    """{camera_id: (model, width, height, [params])} of a cameras.txt."""
    cameras = {}
    with open(path) as f:
        for line in f:
            tokens = line.split()
            if not tokens or tokens[0].startswith("#"):
                continue
            cameras[int(tokens[0])] = (tokens[1], int(tokens[2]),
                                       int(tokens[3]), tokens[4:])
    return cameras


def read_text_images(path):
    """[(image_id, camera_id, name)] of an images.txt (header lines are the
    ones with 10 tokens ending in a non-numeric name)."""
    images = []
    with open(path) as f:
        for line in f:
            tokens = line.split()
            if (len(tokens) == 10 and not tokens[0].startswith("#")
                    and not is_number(tokens[9])):
                images.append((int(tokens[0]), int(tokens[8]), tokens[9]))
    return images


# ---------------------------------------------------------------------------
# Rigs of the rendered sets (cam_from_world poses for sphera_render)


def axis_rotation(axis, angle):
    c, s = math.cos(angle), math.sin(angle)
    if axis == 0:
        return [[1, 0, 0], [0, c, -s], [0, s, c]]
    if axis == 1:
        return [[c, 0, s], [0, 1, 0], [-s, 0, c]]
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)]
            for i in range(3)]


def quaternion_from_matrix(r):
    """(w, x, y, z) of a rotation matrix."""
    trace = r[0][0] + r[1][1] + r[2][2]
    if trace > 0:
        s = 2 * math.sqrt(trace + 1)
        w, x = 0.25 * s, (r[2][1] - r[1][2]) / s
        y, z = (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s
    elif r[0][0] > r[1][1] and r[0][0] > r[2][2]:
        s = 2 * math.sqrt(1 + r[0][0] - r[1][1] - r[2][2])
        w, x = (r[2][1] - r[1][2]) / s, 0.25 * s
        y, z = (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s
    elif r[1][1] > r[2][2]:
        s = 2 * math.sqrt(1 + r[1][1] - r[0][0] - r[2][2])
        w, x = (r[0][2] - r[2][0]) / s, (r[0][1] + r[1][0]) / s
        y, z = 0.25 * s, (r[1][2] + r[2][1]) / s
    else:
        s = 2 * math.sqrt(1 + r[2][2] - r[0][0] - r[1][1])
        w, x = (r[1][0] - r[0][1]) / s, (r[0][2] + r[2][0]) / s
        y, z = (r[1][2] + r[2][1]) / s, 0.25 * s
    return (w, x, y, z) if w >= 0 else (-w, -x, -y, -z)


def rig_line(name, model, width, height, params, centre, yaw_deg,
             pitch_deg=0.0, roll_deg=0.0):
    """A sphera_render rig line. The camera heads `yaw` about the vertical
    (0 = +Z, 90 = +X), then pitches (positive = up, the world's -Y) and
    rolls; centre is in world coordinates (+Y down, floor at y = 1.5)."""
    d = math.pi / 180
    world_from_cam = matmul(matmul(axis_rotation(1, yaw_deg * d),
                                   axis_rotation(0, pitch_deg * d)),
                            axis_rotation(2, roll_deg * d))
    cam_from_world = [[world_from_cam[j][i] for j in range(3)]
                      for i in range(3)]
    t = [-sum(cam_from_world[i][k] * centre[k] for k in range(3))
         for i in range(3)]
    q = quaternion_from_matrix(cam_from_world)
    numbers = " ".join("%.12g" % v for v in list(q) + t)
    return "%s %s %d %d %s | %s" % (name, model, width, height,
                                   " ".join("%.12g" % p for p in params),
                                   numbers)


FISHEYE_PARAMS = [450.56, 450.56, 512, 512, 1.0, 0, 0, 0, 0]  # 190 deg
EQUIRECT_PARAMS = [2048, 1024]
PINHOLE_800_PARAMS = [400, 400, 400, 300]  # 90 deg horizontal


def fisheye190_rig():
    """12 fisheye cameras: the room9 grid plus 3 off-grid, looking in varied
    directions (horizontal, tilted, straight up and down)."""
    poses = [  # centre, yaw, pitch, roll
        ((-1, 0, -1), 45, 0, 0),
        ((0, 0, -1), 0, 60, 0),
        ((1, 0, -1), -45, 0, 10),
        ((-1, 0, 0), 90, -45, 0),
        ((0, 0, 0), 0, 90, 0),
        ((1, 0, 0), -90, -45, 0),
        ((-1, 0, 1), 135, 20, 0),
        ((0, 0, 1), 180, -90, 0),
        ((1, 0, 1), -135, 20, -10),
        ((-0.5, -0.3, -0.5), 200, 0, 0),
        ((0.5, -0.3, 0.5), 20, 0, 0),
        ((0.5, 0.3, -0.5), -90, 30, 15),
    ]
    return [rig_line("fish%02d" % i, "UNIFIED_OMNI", 1024, 1024,
                     FISHEYE_PARAMS, c, yaw, pitch, roll)
            for i, (c, yaw, pitch, roll) in enumerate(poses)]


def hybrid_rig():
    """4 equirect at the grid corners, 4 fisheye at the grid edges, 4 pinhole
    near the centre looking out at the room's corners."""
    lines = []
    for i, (c, yaw) in enumerate([((-1, 0, -1), 10), ((1, 0, -1), 100),
                                  ((-1, 0, 1), 200), ((1, 0, 1), 300)]):
        lines.append(rig_line("eq%d" % i, "EQUIRECTANGULAR", 2048, 1024,
                              EQUIRECT_PARAMS, c, yaw, 2 * (i % 2), -2))
    for i, (c, yaw, pitch) in enumerate([((0, -0.2, -1), 180, 0),
                                         ((1, 0, 0), 90, 30),
                                         ((0, 0.2, 1), 0, -30),
                                         ((-1, 0, 0), -90, 60)]):
        lines.append(rig_line("fish%d" % i, "UNIFIED_OMNI", 1024, 1024,
                              FISHEYE_PARAMS, c, yaw, pitch))
    for i, (c, yaw) in enumerate([((0.3, 0, 0.3), 45), ((-0.3, 0, 0.3), -45),
                                  ((-0.3, 0, -0.3), -135),
                                  ((0.3, 0, -0.3), 135)]):
        lines.append(rig_line("pin%d" % i, "PINHOLE", 800, 600,
                              PINHOLE_800_PARAMS, c, yaw, 5 * (i % 2 * 2 - 1)))
    return lines


def poles_rig():
    """9 upright equirectangular cameras on the room9 grid, alternately 0.6 m
    below the ceiling and 0.6 m above the floor, so that floor and ceiling
    features are seen close to the poles of the panoramas."""
    lines = []
    for k in range(9):
        centre = ((k % 3 - 1) * 0.8, -0.9 if k % 2 == 0 else 0.9,
                  (k // 3 - 1) * 0.8)
        lines.append(rig_line("pole%02d" % k, "EQUIRECTANGULAR", 2048, 1024,
                              EQUIRECT_PARAMS, centre, 0))
    return lines


# Rendered sets: sphera_render arguments (a rig's lines, or layout options).
RENDERED = {
    "room9_equirect": {"layout": ["--layout", "room9", "--model",
                                  "EQUIRECTANGULAR", "--width", "2048",
                                  "--height", "1024"]},
    "room_fisheye190": {"rig": fisheye190_rig},
    "room_hybrid": {"rig": hybrid_rig},
    "room_poles": {"rig": poles_rig},
    "room_pinhole_ring": {"layout": ["--layout", "ring"]},
}


# ---------------------------------------------------------------------------
# The benchmark


class Benchmark:
    def __init__(self, args):
        self.args = args
        self.output_dir = os.path.abspath(args.output_dir)
        self.colmap = os.path.abspath(args.colmap)
        self.stock_colmap = os.path.abspath(args.stock_colmap)
        self.render = os.path.abspath(args.render)
        self.data_dir = os.path.abspath(args.data_dir)
        self.supersample = 2 if args.quick else 3
        self.stock_error = None  # set when the stock build failed
        self.stock_checked = False

    # -- programs ----------------------------------------------------------

    def wait_for(self, path, what):
        deadline = time.monotonic() + 60 * self.args.wait_minutes
        while not os.access(path, os.X_OK):
            if time.monotonic() >= deadline:
                return False
            log("waiting for %s (%s) ..." % (what, path))
            time.sleep(min(60, max(1, deadline - time.monotonic())))
        return True

    def ensure_stock(self):
        if self.stock_checked:
            return self.stock_error
        self.stock_checked = True
        if os.access(self.stock_colmap, os.X_OK):
            return None
        script = os.path.join(REPO_ROOT, "scripts", "build_stock.sh")
        log("stock COLMAP missing: building it with %s (about 25 min)" % script)
        try:
            run_step("build_stock", [script], os.path.join(self.output_dir, "logs"),
                     timeout=4 * 3600)
        except StepError as error:
            self.stock_error = "stock build failed: %s" % error
            return self.stock_error
        if not os.access(self.stock_colmap, os.X_OK):
            self.stock_error = "stock build did not produce " + self.stock_colmap
        return self.stock_error

    # -- scenes --------------------------------------------------------------

    def scene_dir(self, name):
        suffix = "_quick" if self.args.quick else ""
        return os.path.join(self.output_dir, "scenes", name + suffix)

    def ensure_scene(self, name):
        """Renders a synthetic set unless cached; returns its directory."""
        spec = RENDERED[name]
        scene = self.scene_dir(name)
        command = [self.render, "--output", scene, "--seed", str(RENDER_SEED),
                   "--supersample", str(self.supersample)]
        stamp_info = {"supersample": self.supersample, "seed": RENDER_SEED}
        rig_text = None
        if "rig" in spec:
            rig_text = "\n".join(spec["rig"]()) + "\n"
            stamp_info["rig"] = rig_text
        else:
            command += spec["layout"]
            stamp_info["layout"] = spec["layout"]
        stamp_path = os.path.join(scene, "bench_stamp.json")
        complete = os.path.exists(os.path.join(scene, "sparse_gt", "images.txt"))
        if complete and os.path.exists(stamp_path):
            with open(stamp_path) as f:
                try:
                    if json.load(f) != stamp_info:
                        log("%s: cached scene is stale, re-rendering" % name)
                        complete = False
                except ValueError:
                    complete = False
        if complete:
            log("%s: using cached scene %s" % (name, scene))
            return scene
        if not self.wait_for(self.render, "sphera_render"):
            raise StepError("sphera_render not found at %s (build with "
                            "scripts/build.sh)" % self.render)
        shutil.rmtree(scene, ignore_errors=True)
        os.makedirs(os.path.dirname(scene), exist_ok=True)
        if rig_text is not None:
            rig_path = scene + ".rig.txt"
            with open(rig_path, "w") as f:
                f.write(rig_text)
            command += ["--rig", rig_path]
        log("%s: rendering (supersample %d) into %s" %
            (name, self.supersample, scene))
        seconds, _ = run_step("render_" + name, command,
                              os.path.join(self.output_dir, "logs"),
                              self.args.step_timeout)
        log("%s: rendered in %.0f s" % (name, seconds))
        with open(stamp_path, "w") as f:
            json.dump(stamp_info, f, indent=1)
        return scene

    # -- pipeline ------------------------------------------------------------

    def reconstruct(self, colmap, run_dir, image_path, groups, row,
                    mapper_options=()):
        """feature_extractor per camera group, exhaustive_matcher, mapper
        (with extra `mapper_options`). groups: [(model, params or None, image
        list or None)]. Fills the times, num_models and returns the largest
        model's directory."""
        logs = os.path.join(run_dir, "logs")
        database = os.path.join(run_dir, "database.db")
        timeout = self.args.step_timeout
        t_extract = 0.0
        for index, (model, params, image_list) in enumerate(groups):
            command = [colmap, "feature_extractor", "--database_path", database,
                       "--image_path", image_path,
                       "--ImageReader.camera_model", model,
                       "--ImageReader.single_camera_per_folder", "1",
                       "--SiftExtraction.use_gpu", "0"]
            if params:
                command += ["--ImageReader.camera_params",
                            ",".join(str(p) for p in params)]
            if image_list is None:
                # An explicit list: SPHERA's feature_extractor fails on
                # non-image files (a README.md) in the folder.
                image_list = list_images(image_path)
            if image_list:
                list_path = os.path.join(run_dir, "image_list_%d.txt" % index)
                with open(list_path, "w") as f:
                    f.write("\n".join(image_list) + "\n")
                command += ["--image_list_path", list_path]
            step = "feature_extractor" + ("_%d" % index if len(groups) > 1 else "")
            seconds, _ = run_step(step, command, logs, timeout)
            t_extract += seconds
        row["t_extract_s"] = round(t_extract, 3)
        seconds, _ = run_step("exhaustive_matcher",
                              [colmap, "exhaustive_matcher", "--database_path",
                               database, "--SiftMatching.use_gpu", "0"],
                              logs, timeout)
        row["t_match_s"] = round(seconds, 3)
        sparse = os.path.join(run_dir, "sparse")
        os.makedirs(sparse, exist_ok=True)
        seconds, _ = run_step("mapper",
                              [colmap, "mapper", "--database_path", database,
                               "--image_path", image_path, "--output_path",
                               sparse] + list(mapper_options), logs, timeout)
        row["t_map_s"] = round(seconds, 3)
        models = sparse_models(sparse)
        row["num_models"] = len(models)
        if not models:
            raise StepError("mapper produced no model")
        registered, points, path = models[0]
        row["registered"] = registered
        row["points"] = points
        return path

    def evaluate(self, run_dir, model, gt_path, depth_path, row):
        out = os.path.join(run_dir, "eval")
        os.makedirs(out, exist_ok=True)
        command = [self.colmap, "model_evaluator", "--gt_path", gt_path,
                   "--input_path", model, "--output_path", out]
        if depth_path:
            command += ["--depth_path", depth_path]
        run_step("model_evaluator", command, os.path.join(run_dir, "logs"),
                 self.args.step_timeout)
        with open(os.path.join(out, "evaluation.json")) as f:
            e = json.load(f)
        row["registered"] = e.get("num_registered")
        row["total"] = e.get("num_gt_images")
        row["points"] = e.get("num_points3D")
        row["rot_err_mean_deg"] = e.get("mean_rotation_error_deg")
        row["rot_err_max_deg"] = e.get("max_rotation_error_deg")
        row["pos_err_mean"] = e.get("mean_position_error")
        row["pos_err_max"] = e.get("max_position_error")
        row["pos_err_mean_norm"] = e.get("mean_position_error_normalized")
        row["reproj_px"] = e.get("mean_angular_error_px")
        if depth_path and e.get("num_points_with_depth"):
            row["point_err_mean"] = e.get("mean_point_error")
            row["point_err_median"] = e.get("median_point_error")

    def new_run_dir(self, dataset, system):
        run_dir = os.path.join(self.output_dir, "runs", dataset, system)
        shutil.rmtree(run_dir, ignore_errors=True)
        os.makedirs(run_dir)
        return run_dir

    # -- data sets -----------------------------------------------------------

    def rendered_inputs(self, scene, run_dir):
        """Image root, camera groups, GT model and depth directory of a
        rendered set. With several GT cameras (hybrid) every camera's images
        go to their own subfolder (symlinks) and the GT is renamed to match."""
        gt = os.path.join(scene, "sparse_gt")
        cameras = read_text_cameras(os.path.join(gt, "cameras.txt"))
        images = read_text_images(os.path.join(gt, "images.txt"))
        if len(cameras) == 1:
            (model, _, _, params), = cameras.values()
            return (os.path.join(scene, "images"), [(model, params, None)], gt,
                    os.path.join(scene, "depth"))
        folders = {}
        for camera_id, (model, _, _, _) in sorted(cameras.items()):
            folder = model.lower()
            if folder in folders.values():
                folder += "_%d" % camera_id
            folders[camera_id] = folder
        image_root = os.path.join(run_dir, "images")
        gt_root = os.path.join(run_dir, "gt")
        new_gt = os.path.join(gt_root, "sparse")
        depth_root = os.path.join(gt_root, "depth")
        renamed = {}
        for _, camera_id, name in images:
            folder = folders[camera_id]
            renamed[name] = folder + "/" + name
            for root, source in ((image_root, os.path.join(scene, "images", name)),
                                 (depth_root, os.path.join(scene, "depth",
                                                           name + ".depth.bin"))):
                target = os.path.join(root, folder, os.path.basename(source))
                os.makedirs(os.path.dirname(target), exist_ok=True)
                os.symlink(source, target)
        os.makedirs(new_gt, exist_ok=True)
        shutil.copy(os.path.join(gt, "cameras.txt"), new_gt)
        shutil.copy(os.path.join(gt, "points3D.txt"), new_gt)
        with open(os.path.join(gt, "images.txt")) as src, \
                open(os.path.join(new_gt, "images.txt"), "w") as dst:
            for line in src:
                tokens = line.split()
                if (len(tokens) == 10 and not tokens[0].startswith("#")
                        and not is_number(tokens[9])):
                    tokens[9] = renamed[tokens[9]]
                    line = " ".join(tokens) + "\n"
                dst.write(line)
        groups = []
        for camera_id, (model, _, _, params) in sorted(cameras.items()):
            names = [renamed[n] for _, c, n in images if c == camera_id]
            groups.append((model, params, names))
        return image_root, groups, new_gt, depth_root

    def strecha_inputs(self, dataset, run_dir):
        root = os.path.join(self.data_dir, "strecha", dataset)
        image_path = os.path.join(root, "images")
        camera_dir = os.path.join(root, "gt_dense_cameras")
        camera_files = sorted(glob.glob(os.path.join(camera_dir, "*.camera")))
        if not os.path.isdir(image_path) or not camera_files:
            return None
        with open(camera_files[0]) as f:
            k = [float(v) for v in f.read().split()[:9]]
        params = [k[0], k[4], k[2], k[5]]
        gt = os.path.join(run_dir, "gt")
        os.makedirs(gt, exist_ok=True)
        run_step("strecha_importer",
                 [self.colmap, "strecha_importer", "--input_path", camera_dir,
                  "--output_path", gt], os.path.join(run_dir, "logs"),
                 self.args.step_timeout)
        return image_path, [("PINHOLE", params, None)], gt

    def run_one(self, dataset, system):
        row = {"dataset": dataset, "system": system, "status": "ok",
               "timestamp": datetime.datetime.now().isoformat(timespec="seconds"),
               "render": ("ss%d" % self.supersample) if dataset in RENDERED else ""}
        colmap = self.colmap if system == "sphera" else self.stock_colmap
        try:
            if system == "stock":
                error = self.ensure_stock()
                if error:
                    raise StepError(error)
            run_dir = self.new_run_dir(dataset, system)
            if dataset in RENDERED:
                scene = self.ensure_scene(dataset)
                image_path, groups, gt, depth = self.rendered_inputs(scene, run_dir)
                row["total"] = len(read_text_images(os.path.join(gt, "images.txt")))
                log("%s/%s: reconstructing" % (dataset, system))
                model = self.reconstruct(colmap, run_dir, image_path, groups, row)
                self.evaluate(run_dir, model, gt, depth, row)
            elif dataset in ("fountain-P11", "entry-P10"):
                inputs = self.strecha_inputs(dataset, run_dir)
                if inputs is None:
                    row["status"] = "skipped: data not found in %s" % os.path.join(
                        self.data_dir, "strecha", dataset)
                    return row
                image_path, groups, gt = inputs
                row["total"] = len(read_text_images(os.path.join(gt, "images.txt")))
                log("%s/%s: reconstructing" % (dataset, system))
                model = self.reconstruct(colmap, run_dir, image_path, groups, row)
                self.evaluate(run_dir, model, gt, None, row)
            elif dataset == "equirect_flat":
                image_path = os.path.join(self.data_dir, "equirect_flat", "images")
                names = list_images(image_path) if os.path.isdir(image_path) else []
                if not names:
                    row["status"] = "skipped: data not found in " + image_path
                    return row
                row["total"] = len(names)
                width, height = jpeg_size(os.path.join(image_path, names[0]))
                log("%s/%s: reconstructing" % (dataset, system))
                model = self.reconstruct(
                    colmap, run_dir, image_path,
                    [("EQUIRECTANGULAR", [width, height], None)], row)
                _, output = run_step("model_analyzer",
                                     [self.colmap, "model_analyzer", "--path", model],
                                     os.path.join(run_dir, "logs"),
                                     self.args.step_timeout)
                match = re.search(r"Mean reprojection error:\s*([0-9.eE+-]+)", output)
                if match:
                    row["reproj_px"] = float(match.group(1))
                row["status"] = "ok (no ground truth)"
            else:
                raise StepError("unknown data set")
        except StepError as error:
            row["status"] = str(error)
        except Exception as error:  # keep going with the other data sets
            row["status"] = "%s: %s" % (type(error).__name__, error)
        return row


# ---------------------------------------------------------------------------
# Results


def add_ratios(rows):
    by_key = {(r["dataset"], r["system"]): r for r in rows}
    for row in rows:
        row["map_time_ratio"] = ""
        row["rot_err_ratio"] = ""
    for row in rows:
        if row["system"] != "sphera" or row["dataset"] not in STOCK_DATASETS:
            continue
        stock = by_key.get((row["dataset"], "stock"))
        if not stock:
            continue
        for key, ratio_key in (("t_map_s", "map_time_ratio"),
                               ("rot_err_mean_deg", "rot_err_ratio")):
            a, b = to_float(row.get(key)), to_float(stock.get(key))
            if a is not None and b:
                row[ratio_key] = a / b


def sort_rows(rows):
    order = {name: i for i, name in enumerate(DATASETS)}
    return sorted(rows, key=lambda r: (order.get(r["dataset"], 99), r["dataset"],
                                       0 if r["system"] == "sphera" else 1))


def print_table(rows):
    headers = ["dataset", "system", "reg", "models", "points", "rot mean/max",
               "pos mean/max", "pos norm", "reproj px", "pt err mean/med",
               "extract/match/map s", "map t ratio", "rot ratio", "status"]
    table = [headers]
    for r in rows:
        reg = "-"
        if r.get("registered") not in (None, ""):
            reg = "%s/%s" % (fmt(r.get("registered")), fmt(r.get("total")))
        table.append([
            r["dataset"], r["system"], reg, fmt(r.get("num_models")),
            fmt(r.get("points")),
            "%s/%s" % (fmt(r.get("rot_err_mean_deg")), fmt(r.get("rot_err_max_deg"))),
            "%s/%s" % (fmt(r.get("pos_err_mean")), fmt(r.get("pos_err_max"))),
            fmt(r.get("pos_err_mean_norm")), fmt(r.get("reproj_px")),
            "%s/%s" % (fmt(r.get("point_err_mean")), fmt(r.get("point_err_median"))),
            "%s/%s/%s" % (fmt(r.get("t_extract_s"), 2), fmt(r.get("t_match_s"), 2),
                          fmt(r.get("t_map_s"), 2)),
            fmt(r.get("map_time_ratio")), fmt(r.get("rot_err_ratio")),
            r.get("status", ""),
        ])
    widths = [max(len(str(line[i])) for line in table) for i in range(len(headers) - 1)]
    for n, line in enumerate(table):
        print("  ".join(str(c).ljust(w) for c, w in zip(line[:-1], widths))
              + "  " + str(line[-1]))
        if n == 0:
            print("  ".join("-" * w for w in widths) + "  ------")
    print("rot: rotation error (deg); pos: position error (m, after the "
          "similarity alignment); pos norm: / closest GT camera baseline; "
          "reproj: mean angular reprojection error in pixel equivalents "
          "(equirect_flat: model_analyzer's pixels); pt err: 3D point error "
          "(m) against the rendered depth; ratios: SPHERA / stock.")


def write_csv(path, rows):
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: ("" if row.get(k) is None else row.get(k))
                             for k in COLUMNS})
    os.replace(tmp, path)


def read_csv(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return [dict(r) for r in csv.DictReader(f)]


def write_png(path, rows):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        log("matplotlib missing (apt-get install python3-matplotlib): no PNG")
        return False
    datasets = [d for d in DATASETS if any(r["dataset"] == d for r in rows)]
    datasets += sorted({r["dataset"] for r in rows} - set(datasets))
    systems = [s for s in ("sphera", "stock") if any(r["system"] == s for r in rows)]
    by_key = {(r["dataset"], r["system"]): r for r in rows}
    colours = {"sphera": "#1f77b4", "stock": "#ff7f0e"}
    fig, axes = plt.subplots(1, 2, figsize=(max(10, 2.2 * len(datasets)), 4.8))
    width = 0.8 / max(len(systems), 1)
    panels = [("rot_err_mean_deg", "mean rotation error (deg)", True),
              ("t_map_s", "mapping time (s)", False)]
    for ax, (key, title, log_scale) in zip(axes, panels):
        positives = []
        for s_index, system in enumerate(systems):
            xs, ys, missing = [], [], []
            for d_index, dataset in enumerate(datasets):
                x = d_index + (s_index - (len(systems) - 1) / 2) * width
                row = by_key.get((dataset, system))
                value = to_float(row.get(key)) if row else None
                if value is None:
                    if row is not None:
                        missing.append(x)
                    continue
                xs.append(x)
                ys.append(value)
                if value > 0:
                    positives.append(value)
            bars = ax.bar(xs, ys, width, label="SPHERA" if system == "sphera"
                          else "stock COLMAP 3.10", color=colours[system])
            for bar, value in zip(bars, ys):
                ax.annotate(fmt(value, 2), (bar.get_x() + bar.get_width() / 2,
                                            bar.get_height()),
                            ha="center", va="bottom", fontsize=7)
            for x in missing:
                ax.annotate("n/a", (x, 0), ha="center", va="bottom", fontsize=7,
                            color=colours[system], rotation=90,
                            xycoords=("data", "axes fraction"))
        if log_scale and positives and max(positives) / min(positives) > 50:
            ax.set_yscale("log")
        ax.set_title(title)
        ax.set_xticks(range(len(datasets)))
        ax.set_xticklabels(datasets, rotation=30, ha="right", fontsize=8)
        ax.grid(axis="y", alpha=0.3)
        if systems:
            ax.legend(fontsize=8)
    fig.suptitle("SPHERA SfM benchmark")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def make_parser():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", default="",
                        help="comma-separated data sets (default: all)")
    parser.add_argument("--quick", action="store_true",
                        help="smaller renders (supersample 2, cached separately)")
    parser.add_argument("--no_stock", action="store_true",
                        help="no stock COLMAP runs (and no stock build)")
    parser.add_argument("--output_dir", default=os.path.join(REPO_ROOT, "build", "bench"))
    parser.add_argument("--colmap", default=os.path.join(REPO_ROOT, "build", "bin", "colmap"))
    parser.add_argument("--stock_colmap",
                        default=os.path.join(REPO_ROOT, "build-stock", "bin", "colmap"))
    parser.add_argument("--render", default=os.path.join(REPO_ROOT, "build", "synthetic",
                                                         "sphera_render"))
    parser.add_argument("--data_dir", default=os.path.join(REPO_ROOT, "..", "shared", "data"),
                        help="shared real data (strecha/, equirect_flat/)")
    parser.add_argument("--wait_minutes", type=float, default=0,
                        help="wait up to this long for build/bin/colmap and "
                             "sphera_render to appear (polls every 60 s)")
    parser.add_argument("--step_timeout", type=int, default=DEFAULT_STEP_TIMEOUT,
                        help="seconds allowed per command (default %(default)s)")
    parser.add_argument("--fresh", action="store_true",
                        help="do not keep earlier rows in the CSV")
    parser.add_argument("--list", action="store_true", help="list the data sets")
    return parser


def main():
    parser = make_parser()
    args = parser.parse_args()

    if args.list:
        for name in DATASETS:
            print(name + ("  (SPHERA and stock)" if name in STOCK_DATASETS else
                          "  (SPHERA only)"))
        return 0
    selected = [n.strip() for n in args.only.split(",") if n.strip()] or DATASETS
    unknown = [n for n in selected if n not in DATASETS]
    if unknown:
        parser.error("unknown data set(s) %s; known: %s" %
                     (", ".join(unknown), ", ".join(DATASETS)))

    bench = Benchmark(args)
    os.makedirs(bench.output_dir, exist_ok=True)
    if not bench.wait_for(bench.colmap, "SPHERA colmap"):
        print("benchmark_sfm: %s not found; build it with scripts/build.sh "
              "(or pass --colmap, --wait_minutes)" % bench.colmap, file=sys.stderr)
        return 1

    try:
        commands = subprocess.run([bench.colmap, "help"], capture_output=True,
                                  text=True, timeout=60).stdout
    except (OSError, subprocess.TimeoutExpired):
        commands = ""
    for command in ("model_evaluator", "strecha_importer"):
        if command not in commands:
            log("warning: %s has no '%s' command; the steps that need it will "
                "fail" % (bench.colmap, command))

    rows = []
    for dataset in selected:
        systems = ["sphera"]
        if dataset in STOCK_DATASETS and not args.no_stock:
            systems.append("stock")
        for system in systems:
            start = time.monotonic()
            row = bench.run_one(dataset, system)
            log("%s/%s: %s (%.0f s)" % (dataset, system, row["status"],
                                        time.monotonic() - start))
            rows.append(row)

    csv_path = os.path.join(bench.output_dir, "sfm_results.csv")
    png_path = os.path.join(bench.output_dir, "sfm_results.png")
    done = {(r["dataset"], r["system"]) for r in rows}
    kept = [] if args.fresh else [r for r in read_csv(csv_path)
                                  if (r.get("dataset"), r.get("system")) not in done]
    all_rows = sort_rows(rows + kept)
    add_ratios(all_rows)
    print()
    print_table(sort_rows(rows))
    write_csv(csv_path, all_rows)
    print("\nwrote %s%s" % (csv_path, " (also %d row(s) of earlier runs)" % len(kept)
                            if kept else ""))
    if write_png(png_path, all_rows):
        print("wrote " + png_path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
