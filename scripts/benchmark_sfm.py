#!/usr/bin/python3
"""SfM benchmark of SPHERA against unpatched upstream COLMAP of the same base.

Runs the COLMAP command-line pipeline (feature_extractor, exhaustive_matcher,
mapper) on each data set with SPHERA and with the reference system
(unpatched upstream COLMAP 4.x), evaluates the largest model against the
ground truth with SPHERA's `colmap model_evaluator`, and writes a table, two
CSVs and a PNG.

Usage (from the repository root):
  scripts/benchmark_sfm.py                      all data sets, SPHERA and
                                                upstream
  scripts/benchmark_sfm.py --only room9_equirect,fountain-P11
  scripts/benchmark_sfm.py --quick --no_upstream
                                                smaller renders, SPHERA only
  scripts/benchmark_sfm.py --quick --repeats 3 --vary_seed
                                                median and spread of 3 runs
  scripts/benchmark_sfm.py --mapper_options "--Mapper.ba_sphere_residual PIXEL"
                           --label pixel --no_upstream
                                                a second SPHERA setup, added
                                                to the same CSV
  scripts/benchmark_sfm.py --list               the data sets

Data sets (rows):
  room9_equirect     9 equirectangular 2048x1024 cameras, room9 layout
  room_fisheye190    12 UNIFIED_OMNI 190-degree fisheye 1024x1024
  room_fisheye160    the same 12 poses, OPENCV_FISHEYE 160-degree lenses
                     with the renderer's --realistic sensor effects (cropped
                     image circle, vignetting, flare, exposure, noise, JPEG)
  room_eucm160       the same with EUCM 160-degree lenses
  room_thinprism160  the same with THIN_PRISM_FISHEYE 160-degree lenses
  room_hybrid        4 equirect + 4 fisheye + 4 PINHOLE 800x600
  room_poles         9 equirectangular 2048x1024, alternately near floor and
                     ceiling: many features near the poles
  room_pinhole_ring  16 PINHOLE 640x480, ring layout
  fountain-P11       Strecha, 11 perspective 3072x2048
  entry-P10          Strecha, 10 perspective 3072x2048
  equirect_flat      11 real Ricoh Theta 5376x2688, no ground truth

Programs: SPHERA build/bin/colmap and build/synthetic/sphera_render, output
build/bench. Reference "upstream": unpatched upstream COLMAP 4.x at the same
commit (--upstream_colmap, default ~/.cache/sphera-peers/colmap4/build/src/
colmap/exe/colmap, built with ../shared/peers/build_colmap4.sh when missing,
about 40 minutes). It knows EQUIRECTANGULAR, PINHOLE, OPENCV_FISHEYE,
THIN_PRISM_FISHEYE and EUCM (within their hemisphere), so it runs on
room9_equirect, room_fisheye160, room_eucm160, room_thinprism160,
room_poles, room_pinhole_ring, the Strecha sets and equirect_flat; the
190-degree fisheye and hybrid sets get an upstream row "cannot:
camera model UNIFIED_OMNI unknown to upstream". Both systems get the same
command line (--FeatureExtraction.*, --FeatureMatching.*).
SPHERA's program always does the evaluation (model_evaluator,
model_analyzer) and the Strecha import (strecha_importer), whichever system
reconstructed. --no_upstream (or --no_reference) leaves the reference out.

Repeats: with --repeats N every (data set, system) is reconstructed N times
from the same rendered scene; the runs of SPHERA and of the reference
alternate, so that load changes on the machine hit both. COLMAP seeds its
random numbers with 0 in every command (--default_random_seed), so plain
repeats differ only by thread scheduling: the errors hardly move and the
times show the machine's noise. With --vary_seed run k passes seed k-1 to
every command of both systems (run 1 is the default run), so RANSAC differs
from run to run. A system that failed
before its mapper ran (missing data or program, render, extraction or
matching failed) is not repeated. The table and sfm_results.csv give the
median over the successful runs of every number, and for the rotation and
position errors and the extraction, matching, mapping and whole-pipeline
(t_total_s = extract + match + map) times also the spread as min and max
(columns <name>_min, <name>_max; table "median [min..max]"). Ratios
SPHERA / reference (map_time_ratio, total_time_ratio, rot_err_ratio) are
ratios of the medians. runs.csv has one row per single run.

Cramér-Rao bound: for every run with ground truth, scripts/cramer_rao.py
bounds the run's own tracks in the ground-truth poses with the pixel noise
estimated from the model's residuals (sigma_px); rot_crb_deg and pos_crb are
the expected mean errors at the bound (centres protocol, like the errors),
rot_crb_ratio and pos_crb_ratio the measured mean errors over them (table:
rot/CRB, pos/CRB; 1 is the physical limit).

--mapper_options "..." adds options to SPHERA's mapper only (split like a
shell command line); --label NAME names SPHERA's rows (default "sphera"), so
that runs with different options land side by side in one CSV.

Variants: --variant "NAME=OPTIONS" (repeatable) runs, after every SPHERA
run, SPHERA's mapper again with these extra options on the same database
(same matches, same seed) and scores it the same way: rows NAME with
variant_of = the label, their extraction and matching times those of the
SPHERA run, and the ratios variant / SPHERA of the mapping time, rotation
and position errors (map_time_vs_label, rot_err_vs_label,
pos_err_vs_label). This compares mapper options (angular vs pixel residual,
camera-only vs full bundle adjustment) on identical inputs; what remains is
the mapper's own run-to-run spread (its threads make two runs with one
seed differ slightly). --variant_only a,b limits the variants to some sets.

--reuse_extraction: feature extraction (which no seed changes) runs once per
data set and system; the later runs start from a copy of its database and
report its time, so that repeats cost matching and mapping only.

Rendered scenes are cached in OUTPUT_DIR/scenes/<name> (OUTPUT_DIR/scenes/
<name>_quick with --quick) and reused; delete a directory to re-render it.
Each run works in OUTPUT_DIR/runs/<dataset>/<system>/ (<system>/run<k>/ with
--repeats above 1: database, sparse models, evaluation.json, logs/ with
every command's output). Results go to OUTPUT_DIR/sfm_results.csv (one row
per data set and system), OUTPUT_DIR/runs.csv (one row per run),
OUTPUT_DIR/sfm_results.png (errors, times, time ratios) and
OUTPUT_DIR/sfm_bound.png (every run's errors against its Cramér-Rao bound,
by camera type, and error/bound per data set); rows of earlier runs that this run did not redo
are kept in both CSVs unless --fresh (rows of another COLMAP base, from an
older CSV, are dropped). Shared real data (../shared/data by default) may be
absent: those rows are reported as skipped. A failing run is recorded in the
`status` column and does not stop the benchmark.

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
import shlex
import shutil
import struct
import subprocess
import sys
import time

from sphera_common import (REPO_ROOT, SHARED_DATA_DIR, UPSTREAM_COLMAP,
                           eucm160_rig, extract_features, fisheye160_rig,
                           fisheye190_rig,
                           hybrid_rig, thinprism160_rig,
                           match_exhaustive, median, model_counts, poles_rig,
                           read_text_cameras, read_text_images, run_logged)

# Data sets and the camera models their images use.
DATASET_MODELS = {
    "room9_equirect": ["EQUIRECTANGULAR"],
    "room_fisheye190": ["UNIFIED_OMNI"],
    "room_fisheye160": ["OPENCV_FISHEYE"],
    "room_eucm160": ["EUCM"],
    "room_thinprism160": ["THIN_PRISM_FISHEYE"],
    "room_hybrid": ["EQUIRECTANGULAR", "UNIFIED_OMNI", "PINHOLE"],
    "room_poles": ["EQUIRECTANGULAR"],
    "room_pinhole_ring": ["PINHOLE"],
    "fountain-P11": ["PINHOLE"],
    "entry-P10": ["PINHOLE"],
    "equirect_flat": ["EQUIRECTANGULAR"],
}
DATASETS = list(DATASET_MODELS)

# The COLMAP base SPHERA is built on (the `base` column of the CSVs), and
# the unpatched reference of that base: upstream COLMAP at the same commit.
# REFERENCE_MODELS: the models the reference knows among those above; data
# sets with other models get an explicit "cannot" row of the reference.
BASE = "4"
BUILD_DIR = os.path.join(REPO_ROOT, "build")
BUILD_HINT = "scripts/build.sh"
REFERENCE = "upstream"
REFERENCE_TITLE = "upstream COLMAP 4.x"
REFERENCE_MODELS = {"PINHOLE", "EQUIRECTANGULAR", "OPENCV_FISHEYE",
                    "THIN_PRISM_FISHEYE", "EUCM"}
REFERENCE_BUILDER = os.path.normpath(os.path.join(
    REPO_ROOT, "..", "shared", "peers", "build_colmap4.sh"))
REFERENCE_BUILD_MINUTES = 40
REFERENCE_SYSTEMS = {REFERENCE}
# Command-line names of COLMAP 4.x, the same for both systems (and those
# of sphera_common's extract_features, match_exhaustive).
SEED_OPTION = "--default_random_seed"
DEFAULT_LABEL = "sphera"

# Numbers of a run, summarised over the repeats by their median; SPREAD_KEYS
# also get <key>_min and <key>_max columns (the spread).
COUNT_KEYS = ["registered", "total", "num_models", "points"]
METRIC_KEYS = COUNT_KEYS + [
    "rot_err_mean_deg", "rot_err_max_deg", "pos_err_mean", "pos_err_max",
    "pos_err_mean_norm", "reproj_px", "point_err_mean", "point_err_median",
    "t_extract_s", "t_match_s", "t_map_s", "t_total_s",
    "sigma_px", "rot_crb_deg", "pos_crb", "rot_crb_ratio", "pos_crb_ratio",
]
SPREAD_KEYS = ["rot_err_mean_deg", "pos_err_mean", "t_extract_s", "t_match_s",
               "t_map_s", "t_total_s", "rot_crb_ratio", "pos_crb_ratio"]
# (median compared, ratio column): SPHERA / reference of the same base.
RATIOS = [("t_map_s", "map_time_ratio"), ("t_total_s", "total_time_ratio"),
          ("rot_err_mean_deg", "rot_err_ratio"), ("pos_err_mean", "pos_err_ratio")]
# (median compared, ratio column): a variant (--variant) / SPHERA's own
# rows (--label) of the same data set.
VARIANT_RATIOS = [("t_map_s", "map_time_vs_label"),
                  ("rot_err_mean_deg", "rot_err_vs_label"),
                  ("pos_err_mean", "pos_err_vs_label")]


def with_spread(keys):
    """keys, each of SPREAD_KEYS followed by its _min and _max column."""
    columns = []
    for key in keys:
        columns.append(key)
        if key in SPREAD_KEYS:
            columns += [key + "_min", key + "_max"]
    return columns


COLUMNS = (["dataset", "system", "base", "status", "runs", "runs_ok"]
           + with_spread(METRIC_KEYS) + [ratio for _, ratio in RATIOS]
           + [ratio for _, ratio in VARIANT_RATIOS]
           + ["variant_of", "mapper_options", "render", "timestamp"])
RUN_COLUMNS = (["dataset", "system", "base", "repeat", "seed", "status"] + METRIC_KEYS
               + ["variant_of", "extraction_reused", "mapper_options", "render",
                  "timestamp", "run_dir"])

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


def now():
    return datetime.datetime.now().isoformat(timespec="seconds")


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


def record_failure(row, error):
    """The status of a run that stopped on `error`: a failed step's message,
    or the type and message of anything else."""
    row["status"] = (str(error) if isinstance(error, StepError)
                     else "%s: %s" % (type(error).__name__, error))


def run_step(name, command, log_dir, timeout):
    """Runs `command`, logging to log_dir/name.log; returns (seconds, output).
    Raises StepError on a non-zero exit or timeout."""
    os.makedirs(log_dir, exist_ok=True)
    log_path = os.path.join(log_dir, name + ".log")
    env = dict(os.environ)
    env.setdefault("QT_QPA_PLATFORM", "offscreen")
    try:
        returncode, seconds = run_logged(command, log_path, timeout, env=env,
                                         cwd=REPO_ROOT)
    except subprocess.TimeoutExpired:
        raise StepError("%s timed out after %d s (log %s)" %
                        (name, timeout, log_path))
    except OSError as error:
        raise StepError("%s: cannot run %s: %s" % (name, command[0], error))
    with open(log_path, errors="replace") as log_file:
        output = log_file.read()
    if returncode != 0:
        raise StepError("%s failed (exit %d): %s" %
                        (name, returncode, error_summary(output)))
    return seconds, output


def sparse_models(sparse_dir):
    """Sub-model directories of a mapper output, largest first."""
    models = []
    for path in sorted(glob.glob(os.path.join(sparse_dir, "*"))):
        if not os.path.isdir(path):
            continue
        counts = model_counts(path)
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


# Rendered sets: sphera_render arguments (a rig's lines, or layout options).
RENDERED = {
    "room9_equirect": {"layout": ["--layout", "room9", "--model",
                                  "EQUIRECTANGULAR", "--width", "2048",
                                  "--height", "1024"]},
    "room_fisheye190": {"rig": fisheye190_rig},
    "room_fisheye160": {"rig": fisheye160_rig, "options": ["--realistic"]},
    "room_eucm160": {"rig": eucm160_rig, "options": ["--realistic"]},
    "room_thinprism160": {"rig": thinprism160_rig,
                          "options": ["--realistic"]},
    "room_hybrid": {"rig": hybrid_rig},
    "room_poles": {"rig": poles_rig},
    "room_pinhole_ring": {"layout": ["--layout", "ring"]},
}


# ---------------------------------------------------------------------------
# The benchmark


def unknown_models(dataset):
    """The camera models of `dataset` that the reference lacks."""
    return [m for m in DATASET_MODELS[dataset] if m not in REFERENCE_MODELS]


class Benchmark:
    def __init__(self, args):
        """Programs and directories from the options; those left empty take
        the defaults in build/. Raises ValueError on --mapper_options that
        do not split."""
        self.args = args
        self.output_dir = os.path.abspath(args.output_dir
                                          or os.path.join(BUILD_DIR, "bench"))
        self.colmap = os.path.abspath(args.colmap
                                      or os.path.join(BUILD_DIR, "bin", "colmap"))
        self.render = os.path.abspath(
            args.render or os.path.join(BUILD_DIR, "synthetic", "sphera_render"))
        self.data_dir = os.path.abspath(args.data_dir)
        self.supersample = 2 if args.quick else 3
        self.label = args.label
        self.mapper_options = shlex.split(args.mapper_options)
        self.variants = []  # [(name, mapper options)]
        for text in args.variant:
            name, _, options = text.partition("=")
            self.variants.append((name.strip(), shlex.split(options)))
        self.variant_datasets = set(
            [d.strip() for d in args.variant_only.split(",") if d.strip()]
            or DATASETS)
        self.reference = REFERENCE
        self.reference_colmap = os.path.abspath(args.upstream_colmap)
        self.reference_error = None  # set when the reference is unavailable
        self.reference_checked = False

    # -- programs ----------------------------------------------------------

    def wait_for(self, path, what):
        deadline = time.monotonic() + 60 * self.args.wait_minutes
        while not os.access(path, os.X_OK):
            if time.monotonic() >= deadline:
                return False
            log("waiting for %s (%s) ..." % (what, path))
            time.sleep(min(60, max(1, deadline - time.monotonic())))
        return True

    def ensure_reference(self):
        """None when the reference program is there (building it first when
        missing), else why it is not."""
        if self.reference_checked:
            return self.reference_error
        self.reference_checked = True
        if os.access(self.reference_colmap, os.X_OK):
            return None
        title = REFERENCE_TITLE
        script = REFERENCE_BUILDER
        if not os.path.exists(script):
            folder = os.path.dirname(script)
            self.reference_error = "cannot build %s: %s" % (
                title, ("%s is absent" % folder) if not os.path.isdir(folder)
                else "no %s in %s" % (os.path.basename(script), folder))
            return self.reference_error
        log("%s missing (%s): building it with %s (about %d min)" %
            (title, self.reference_colmap, script,
             REFERENCE_BUILD_MINUTES))
        try:
            _, output = run_step("build_" + self.reference, [script],
                                 os.path.join(self.output_dir, "logs"),
                                 timeout=4 * 3600)
        except StepError as error:
            self.reference_error = "%s build failed: %s" % (self.reference, error)
            return self.reference_error
        # build_colmap4.sh prints the program's path on its last line.
        lines = output.strip().splitlines()
        built = lines[-1].strip() if lines else ""
        if not os.access(self.reference_colmap, os.X_OK) and os.path.isabs(built) \
                and os.access(built, os.X_OK):
            log("using %s" % built)
            self.reference_colmap = built
        if not os.access(self.reference_colmap, os.X_OK):
            self.reference_error = "%s build did not produce %s" % (
                self.reference, self.reference_colmap)
        return self.reference_error

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
        if "options" in spec:
            command += spec["options"]
            stamp_info["options"] = spec["options"]
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
                            "%s)" % (self.render, BUILD_HINT))
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
                    mapper_options=(), seed=None, extracted=None):
        """feature_extractor per camera group, exhaustive_matcher, mapper
        (with extra `mapper_options`) with COLMAP 4.x's option names;
        every command with the random seed `seed` unless None (COLMAP's
        default seed is 0). groups: [(model, params or None, image list or
        None)]. extracted: None, or the path under which the database after
        extraction is kept for later runs (and taken from, with its time,
        when an earlier run left it). Fills the times (t_total_s: their
        sum), num_models and returns the largest model's directory."""
        logs = os.path.join(run_dir, "logs")
        database = os.path.join(run_dir, "database.db")
        row["database"] = database
        timeout = self.args.step_timeout
        seeded = [] if seed is None else [SEED_OPTION, str(seed)]
        if extracted and os.path.exists(extracted + ".json"):
            with open(extracted + ".json") as f:
                row["t_extract_s"] = json.load(f)["t_extract_s"]
            shutil.copyfile(extracted, database)
            row["extraction_reused"] = 1
            log("reusing the extraction of %s (%.1f s)" %
                (os.path.dirname(extracted), row["t_extract_s"]))
        else:
            self.extract(colmap, run_dir, database, image_path, groups, row,
                         seeded)
            if extracted:
                shutil.copyfile(database, extracted)
                with open(extracted + ".json", "w") as f:
                    json.dump({"t_extract_s": row["t_extract_s"]}, f)
        seconds, _ = match_exhaustive(database, *seeded,
                                      program=self.step(colmap, logs,
                                                        "exhaustive_matcher"))
        row["t_match_s"] = round(seconds, 3)
        return self.map(colmap, run_dir, database, image_path, row,
                        mapper_options, seed)

    def step(self, colmap, logs, name):
        """A `program` for extract_features and match_exhaustive: runs
        `colmap ARGS` as the step NAME, returns (seconds, output)."""
        def run(*args):
            return run_step(name, [colmap, *map(str, args)], logs,
                            self.args.step_timeout)
        return run

    def map(self, colmap, run_dir, database, image_path, row, mapper_options,
            seed):
        """The mapper on `database` into run_dir/sparse; fills t_map_s,
        t_total_s, num_models, registered, points and returns the largest
        model's directory."""
        seeded = [] if seed is None else [SEED_OPTION, str(seed)]
        sparse = os.path.join(run_dir, "sparse")
        os.makedirs(sparse, exist_ok=True)
        seconds, _ = run_step("mapper",
                              [colmap, "mapper", "--database_path", database,
                               "--image_path", image_path, "--output_path",
                               sparse] + seeded + list(mapper_options),
                              os.path.join(run_dir, "logs"),
                              self.args.step_timeout)
        row["t_map_s"] = round(seconds, 3)
        row["t_total_s"] = round(row["t_extract_s"] + row["t_match_s"] +
                                 row["t_map_s"], 3)
        models = sparse_models(sparse)
        row["num_models"] = len(models)
        if not models:
            raise StepError("mapper produced no model")
        registered, points, path = models[0]
        row["registered"] = registered
        row["points"] = points
        return path

    def extract(self, colmap, run_dir, database, image_path, groups, row,
                seeded):
        """feature_extractor per camera group into `database`; fills
        t_extract_s."""
        logs = os.path.join(run_dir, "logs")

        t_extract = 0.0
        for index, (model, params, image_list) in enumerate(groups):
            options = ["--ImageReader.single_camera_per_folder", "1"] + seeded
            if image_list is None:
                # An explicit list: SPHERA's feature_extractor fails on
                # non-image files (a README.md) in the folder.
                image_list = list_images(image_path)
            if image_list:
                list_path = os.path.join(run_dir, "image_list_%d.txt" % index)
                with open(list_path, "w") as f:
                    f.write("\n".join(image_list) + "\n")
                options += ["--image_list_path", list_path]
            name = "feature_extractor" + ("_%d" % index if len(groups) > 1 else "")
            seconds, _ = extract_features(
                database, image_path, model, *options, params=params or None,
                single_camera=False, program=self.step(colmap, logs, name))
            t_extract += seconds
        row["t_extract_s"] = round(t_extract, 3)

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
        self.bound(run_dir, model, gt_path, row)

    def bound(self, run_dir, model, gt_path, row):
        """The Cramér-Rao bound of the model's own tracks in the ground-truth
        poses, with the pixel noise estimated from its residuals
        (scripts/cramer_rao.py), and the ratios of the measured mean errors
        to the expected mean errors at the bound (centres protocol)."""
        import cramer_rao
        text = os.path.join(run_dir, "eval", "text")
        os.makedirs(text, exist_ok=True)
        run_step("model_converter",
                 [self.colmap, "model_converter", "--input_path", model,
                  "--output_path", text, "--output_type", "TXT"],
                 os.path.join(run_dir, "logs"), self.args.step_timeout)
        try:
            bound = cramer_rao.bound_for_reconstruction(gt_path, text)
        except (OSError, ValueError) as error:
            log("no Cramér-Rao bound for %s: %s" % (model, error))
            return
        row["sigma_px"] = bound["sigma_px_estimated"]
        row["rot_crb_deg"] = bound["rot_expected_mean_deg"]
        row["pos_crb"] = bound["pos_expected_mean"]
        row["rot_crb_ratio"] = row["rot_err_mean_deg"] / row["rot_crb_deg"]
        row["pos_crb_ratio"] = row["pos_err_mean"] / row["pos_crb"]

    def analyze(self, run_dir, model, row):
        """model_analyzer's mean reprojection error, for a set without
        ground truth."""
        _, output = run_step("model_analyzer",
                             [self.colmap, "model_analyzer", "--path", model],
                             os.path.join(run_dir, "logs"), self.args.step_timeout)
        match = re.search(r"Mean reprojection error:\s*([0-9.eE+-]+)", output)
        if match:
            row["reproj_px"] = float(match.group(1))

    def new_run_dir(self, dataset, system, repeat=None):
        """An empty OUTPUT_DIR/runs/<dataset>/<system>[/run<repeat>]."""
        run_dir = os.path.join(self.output_dir, "runs", dataset, system)
        if repeat is not None:
            run_dir = os.path.join(run_dir, "run%d" % repeat)
        shutil.rmtree(run_dir, ignore_errors=True)
        os.makedirs(run_dir)
        return run_dir

    # -- data sets -----------------------------------------------------------

    def rendered_inputs(self, scene, run_dir):
        """Image root, camera groups, GT model and depth directory of a
        rendered set. With several GT cameras (hybrid) every camera's images
        go to their own subfolder (symlinks) and the GT is renamed to match."""
        gt = os.path.join(scene, "sparse_gt")
        cameras = read_text_cameras(gt)
        images = [(int(fields[8]), fields[9])
                  for fields, _ in read_text_images(gt).values()]
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
        for camera_id, name in images:
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
            names = [renamed[n] for c, n in images if c == camera_id]
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
                  "--output_path", gt, "--output_type", "TXT"],
                 os.path.join(run_dir, "logs"), self.args.step_timeout)
        return image_path, [("PINHOLE", params, None)], gt

    def run_one(self, dataset, system, repeat=1):
        """One reconstruction and evaluation of `dataset` by `system` (the
        SPHERA label or the reference); returns the run's row."""
        is_reference = system == self.reference
        seed = repeat - 1 if self.args.vary_seed else None
        row = {"dataset": dataset, "system": system, "base": BASE,
               "repeat": repeat, "seed": "" if seed is None else seed,
               "status": "ok",
               "mapper_options": "" if is_reference
               else shlex.join(self.mapper_options),
               "timestamp": now(),
               "render": ("ss%d" % self.supersample) if dataset in RENDERED else ""}
        colmap = self.reference_colmap if is_reference else self.colmap
        mapper_options = () if is_reference else self.mapper_options
        try:
            if is_reference:
                error = self.ensure_reference()
                if error:
                    raise StepError(error)
            run_dir = self.new_run_dir(dataset, system,
                                       repeat if self.args.repeats > 1 else None)
            row["run_dir"] = run_dir
            gt = depth = None
            if dataset in RENDERED:
                scene = self.ensure_scene(dataset)
                image_path, groups, gt, depth = self.rendered_inputs(scene, run_dir)
            elif dataset in ("fountain-P11", "entry-P10"):
                inputs = self.strecha_inputs(dataset, run_dir)
                if inputs is None:
                    row["status"] = "skipped: data not found in %s" % os.path.join(
                        self.data_dir, "strecha", dataset)
                    return row
                image_path, groups, gt = inputs
            elif dataset == "equirect_flat":
                image_path = os.path.join(self.data_dir, "equirect_flat", "images")
                names = list_images(image_path) if os.path.isdir(image_path) else []
                if not names:
                    row["status"] = "skipped: data not found in " + image_path
                    return row
                row["total"] = len(names)
                width, height = jpeg_size(os.path.join(image_path, names[0]))
                groups = [("EQUIRECTANGULAR", [width, height], None)]
            else:
                raise StepError("unknown data set")
            if gt:
                row["total"] = len(read_text_images(gt))
            row["inputs"] = (image_path, gt, depth)
            log("%s/%s run %d: reconstructing" % (dataset, system, repeat))
            model = self.reconstruct(colmap, run_dir, image_path, groups, row,
                                     mapper_options, seed,
                                     self.extracted_path(dataset, system))
            self.score(run_dir, model, gt, depth, row)
        except Exception as error:  # keep going with the other data sets
            record_failure(row, error)
        return row

    def score(self, run_dir, model, gt, depth, row):
        """Errors against the ground truth `gt` (and the bound), or without
        one model_analyzer's reprojection error."""
        if gt:
            self.evaluate(run_dir, model, gt, depth, row)
        else:
            self.analyze(run_dir, model, row)
            row["status"] = "ok (no ground truth)"

    def extracted_path(self, dataset, system):
        """Where runs of (dataset, system) keep the database after feature
        extraction for the next runs (--reuse_extraction), else None."""
        if not self.args.reuse_extraction:
            return None
        return os.path.join(self.output_dir, "runs", dataset, system,
                            "extracted.db")

    def run_variant(self, dataset, base, name, options, repeat):
        """SPHERA's mapper with the variant's `options` (after the label's
        own --mapper_options) on the database of the SPHERA run `base`, with
        its seed, scored like it; returns the variant's row (extraction and
        matching times are those of `base`)."""
        seed = repeat - 1 if self.args.vary_seed else None
        options = list(self.mapper_options) + list(options)
        row = {"dataset": dataset, "system": name, "base": BASE,
               "repeat": repeat, "seed": "" if seed is None else seed,
               "status": "ok", "variant_of": self.label,
               "mapper_options": shlex.join(options), "timestamp": now(),
               "render": base.get("render", "")}
        try:
            if "t_match_s" not in base or "inputs" not in base:
                raise StepError("no matched database: %s" % base["status"])
            image_path, gt, depth = base["inputs"]
            run_dir = self.new_run_dir(dataset, name,
                                       repeat if self.args.repeats > 1 else None)
            row["run_dir"] = run_dir
            row["total"] = base.get("total")
            for key in ("t_extract_s", "t_match_s", "extraction_reused"):
                if key in base:
                    row[key] = base[key]
            log("%s/%s run %d: mapper on %s" % (dataset, name, repeat,
                                                 base["database"]))
            model = self.map(self.colmap, run_dir, base["database"], image_path,
                             row, options, seed)
            self.score(run_dir, model, gt, depth, row)
        except Exception as error:  # keep going with the other data sets
            record_failure(row, error)
        return row

    def run_dataset(self, dataset):
        """Runs SPHERA and (where it applies) the reference args.repeats
        times each, alternating between them; a system that failed before
        its mapper ran (no data, no program, render or extraction failed) is
        not run again. Returns (the rows of the single runs, one summary row
        per system including the reference's "cannot" row)."""
        systems = [self.label]
        cannot = []
        unknown = unknown_models(dataset)
        if not self.args.no_upstream and not unknown:
            systems.append(self.reference)
        elif not self.args.no_upstream:
            cannot.append({
                "dataset": dataset, "system": self.reference,
                "base": BASE, "runs": 0, "runs_ok": 0,
                "status": "cannot: camera model %s unknown to %s" %
                          ("/".join(unknown), self.reference),
                "timestamp": now()})
        for system in systems:
            extracted = self.extracted_path(dataset, system)
            for path in (extracted, extracted and extracted + ".json"):
                if path and os.path.exists(path):
                    os.remove(path)  # never an extraction of an earlier call
        variants = self.variants if dataset in self.variant_datasets else []
        runs = {system: [] for system in systems + [n for n, _ in variants]}
        for repeat in range(1, self.args.repeats + 1):
            for system in systems:
                done = runs[system]
                if done and not is_ok(done[-1]) and "t_match_s" not in done[-1]:
                    continue  # failed before the mapper: repeating cannot help
                start = time.monotonic()
                row = self.run_one(dataset, system, repeat)
                log("%s/%s run %d/%d: %s (%.0f s)" % (
                    dataset, system, repeat, self.args.repeats, row["status"],
                    time.monotonic() - start))
                done.append(row)
                if system != self.label:
                    continue
                for name, options in variants:
                    start = time.monotonic()
                    variant = self.run_variant(dataset, row, name, options, repeat)
                    log("%s/%s run %d/%d: %s (%.0f s)" % (
                        dataset, name, repeat, self.args.repeats,
                        variant["status"], time.monotonic() - start))
                    runs[name].append(variant)
        return ([row for rows in runs.values() for row in rows],
                [summarize(rows) for rows in runs.values() if rows] + cannot)


# ---------------------------------------------------------------------------
# Results


def is_ok(row):
    return str(row.get("status", "")).startswith("ok")


def summarize(runs):
    """The row of one (data set, system) from its runs: the median of every
    number over the successful runs, the min and max of SPREAD_KEYS, and a
    status that names the failed runs."""
    last = runs[-1]
    summary = {key: last.get(key, "") for key in
               ("dataset", "system", "base", "variant_of", "mapper_options",
                "render", "timestamp")}
    ok = [r for r in runs if is_ok(r)]
    failed = [r for r in runs if not is_ok(r)]
    summary["runs"], summary["runs_ok"] = len(runs), len(ok)
    for key in METRIC_KEYS:
        values = [v for v in (to_float(r.get(key)) for r in ok) if v is not None]
        if not values:
            continue
        value = median(values)
        summary[key] = int(value) if key in COUNT_KEYS and value.is_integer() else value
        if key in SPREAD_KEYS:
            summary[key + "_min"], summary[key + "_max"] = min(values), max(values)
    if not failed:
        summary["status"] = ok[0]["status"]
    elif len(runs) == 1:
        summary["status"] = failed[0]["status"]
    else:
        first = "run %d: %s" % (failed[0]["repeat"], failed[0]["status"])
        summary["status"] = ("%s in %d of %d runs; %s" % (ok[0]["status"], len(ok),
                                                        len(runs), first)
                             if ok else "all %d runs failed; %s" % (len(runs), first))
    return summary


def row_key(row):
    """(base, data set, system)."""
    return (row.get("base") or "", row.get("dataset"), row.get("system"))


def add_ratios(rows):
    """SPHERA / reference of the medians in RATIOS, between rows of the same
    base and data set; a variant / its SPHERA label in VARIANT_RATIOS."""
    references = {row_key(r)[:2]: r for r in rows
                  if r.get("system") in REFERENCE_SYSTEMS}
    by_key = {row_key(r): r for r in rows}
    for row in rows:
        label = by_key.get(row_key(row)[:2] + (row.get("variant_of"),))
        for key, ratio_key in VARIANT_RATIOS:
            row[ratio_key] = ""
            a = to_float(row.get(key))
            b = to_float(label.get(key)) if label and row.get("variant_of") else None
            if a is not None and b:
                row[ratio_key] = a / b
        reference = None
        if row.get("system") not in REFERENCE_SYSTEMS:
            reference = references.get(row_key(row)[:2])
        for key, ratio_key in RATIOS:
            row[ratio_key] = ""
            a = to_float(row.get(key))
            b = to_float(reference.get(key)) if reference else None
            if a is not None and b:
                row[ratio_key] = a / b


def system_order(system):
    """SPHERA's default label first, then other labels, references last."""
    return (system in REFERENCE_SYSTEMS, system != DEFAULT_LABEL, system)


def sort_rows(rows):
    order = {name: i for i, name in enumerate(DATASETS)}
    return sorted(rows, key=lambda r: (order.get(r["dataset"], 99), r["dataset"],
                                       system_order(r["system"]),
                                       to_float(r.get("repeat")) or 0))


def spread_cell(row, key, digits=3):
    """'median [min..max]' (just the median after a single good run)."""
    text = fmt(row.get(key), digits)
    low, high = to_float(row.get(key + "_min")), to_float(row.get(key + "_max"))
    if low is not None and high is not None and (to_float(row.get("runs_ok")) or 0) > 1:
        text += " [%s..%s]" % (fmt(low, digits), fmt(high, digits))
    return text


def pair_cell(row, first, second):
    return "%s/%s" % (fmt(row.get(first)), fmt(row.get(second)))


TABLE_COLUMNS = [  # (header, cell of a row)
    ("dataset", lambda r: r["dataset"]),
    ("system", lambda r: r["system"]),
    ("runs", lambda r: pair_cell(r, "runs_ok", "runs") if to_float(r.get("runs")) else "-"),
    ("reg", lambda r: pair_cell(r, "registered", "total")
     if r.get("registered") not in (None, "") else "-"),
    ("models", lambda r: fmt(r.get("num_models"))),
    ("points", lambda r: fmt(r.get("points"))),
    ("rot mean", lambda r: spread_cell(r, "rot_err_mean_deg")),
    ("rot max", lambda r: fmt(r.get("rot_err_max_deg"))),
    ("pos mean", lambda r: spread_cell(r, "pos_err_mean")),
    ("pos max", lambda r: fmt(r.get("pos_err_max"))),
    ("pos norm", lambda r: fmt(r.get("pos_err_mean_norm"))),
    ("reproj px", lambda r: fmt(r.get("reproj_px"))),
    ("pt err mean/med", lambda r: pair_cell(r, "point_err_mean", "point_err_median")),
    ("extract s", lambda r: spread_cell(r, "t_extract_s", 2)),
    ("match s", lambda r: spread_cell(r, "t_match_s", 2)),
    ("map s", lambda r: spread_cell(r, "t_map_s", 2)),
    ("total s", lambda r: spread_cell(r, "t_total_s", 2)),
    ("map t ratio", lambda r: fmt(r.get("map_time_ratio"))),
    ("total t ratio", lambda r: fmt(r.get("total_time_ratio"))),
    ("rot ratio", lambda r: fmt(r.get("rot_err_ratio"))),
    ("pos ratio", lambda r: fmt(r.get("pos_err_ratio"))),
    ("rot/CRB", lambda r: spread_cell(r, "rot_crb_ratio")),
    ("pos/CRB", lambda r: spread_cell(r, "pos_crb_ratio")),
    ("vs label map/rot/pos", lambda r: "/".join(
        fmt(r.get(k)) for _, k in VARIANT_RATIOS) if r.get("variant_of") else ""),
    ("status", lambda r: r.get("status", "")),
]


def print_table(rows, reference):
    table = [[header for header, _ in TABLE_COLUMNS]]
    table += [[cell(r) for _, cell in TABLE_COLUMNS] for r in rows]
    widths = [max(len(str(line[i])) for line in table)
              for i in range(len(TABLE_COLUMNS) - 1)]
    for n, line in enumerate(table):
        print("  ".join(str(c).ljust(w) for c, w in zip(line[:-1], widths))
              + "  " + str(line[-1]))
        if n == 0:
            print("  ".join("-" * w for w in widths) + "  ------")
    print("runs: successful/attempted runs; every number is the median over "
          "the successful runs, [a..b] their min..max (the spread). rot: "
          "rotation error (deg); pos: position error (m, after the similarity "
          "alignment); pos norm: / closest GT camera baseline; reproj: mean "
          "angular reprojection error in pixel equivalents (equirect_flat: "
          "model_analyzer's pixels); pt err: 3D point error (m) against the "
          "rendered depth; total: extract+match+map; ratios: SPHERA / %s of "
          "the medians; rot/CRB, pos/CRB: mean error over the expected mean "
          "error at the Cramér-Rao bound of the run's own tracks; vs label: "
          "a variant (same database, other mapper options) over SPHERA's "
          "rows, map time/rotation/position." % reference)


def write_csv(path, rows, columns):
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: ("" if row.get(k) is None else row.get(k))
                             for k in columns})
    os.replace(tmp, path)


def read_csv(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return [dict(r) for r in csv.DictReader(f)]


def merge_earlier(path, rows, fresh):
    """`rows` and, unless `fresh`, the rows of the CSV at `path` for other
    (data set, system) of this base; returns them sorted, and the number
    kept. Rows of another COLMAP base (an older CSV) are dropped."""
    done = {row_key(r) for r in rows}
    earlier = [] if fresh else read_csv(path)
    kept = [r for r in earlier if r.get("base") == BASE and row_key(r) not in done]
    dropped = sum(1 for r in earlier if r.get("base") != BASE)
    if dropped:
        log("%s: dropped %d row(s) of another COLMAP base" % (path, dropped))
    return sort_rows(rows + kept), len(kept)


def system_title(system):
    if system == REFERENCE:
        return REFERENCE_TITLE
    return "SPHERA" if system == DEFAULT_LABEL else "SPHERA " + system


PNG_BARS = [  # (column, title, log scale when the values span 50x)
    ("rot_err_mean_deg", "mean rotation error (deg)", True),
    ("pos_err_mean", "mean position error (m)", True),
    ("t_total_s", "extract+match+map time (s)", False),
    None,  # the ratio panel
    ("t_extract_s", "extraction time (s)", False),
    ("t_match_s", "matching time (s)", False),
    ("t_map_s", "mapping time (s)", False),
]
PNG_RATIOS = [("map_time_ratio", "mapping"),
              ("total_time_ratio", "extract+match+map")]
COLOURS = ["#1f77b4", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf"]
REFERENCE_COLOUR = "#ff7f0e"


def bar_value(row, key):
    """(median, min, max) of `key` in `row` (min, max None without a
    spread); None when the value is missing, False when there is no row."""
    if row is None:
        return False
    value = to_float(row.get(key))
    if value is None:
        return None
    return value, to_float(row.get(key + "_min")), to_float(row.get(key + "_max"))


def draw_bars(ax, datasets, series, log_scale):
    """Grouped bars, one group per data set. series: [(label, bar style,
    [bar_value(...) per data set])]; None is marked n/a, False left empty;
    min and max give the error bar."""
    width = 0.8 / max(len(series), 1)
    positives = []
    for s_index, (label, style, values) in enumerate(series):
        xs, ys, errors = [], [], [[], []]
        for d_index, value in enumerate(values):
            x = d_index + (s_index - (len(series) - 1) / 2) * width
            if value is None:
                ax.annotate("n/a", (x, 0), ha="center", va="bottom", fontsize=7,
                            color=style["color"], rotation=90,
                            xycoords=("data", "axes fraction"))
            if not value:
                continue
            y, low, high = value
            xs.append(x)
            ys.append(y)
            errors[0].append(y - low if low is not None else 0)
            errors[1].append(high - y if high is not None else 0)
            positives += [v for v in (y, low, high) if v is not None and v > 0]
        has_spread = any(errors[0]) or any(errors[1])
        bars = ax.bar(xs, ys, width, label=label, yerr=errors if has_spread else None,
                      capsize=2, error_kw={"elinewidth": 0.8}, **style)
        for bar, y, above in zip(bars, ys, errors[1]):
            ax.annotate(fmt(y, 2), (bar.get_x() + bar.get_width() / 2, y + above),
                        ha="center", va="bottom", fontsize=6)
    if log_scale and positives and max(positives) / min(positives) > 50:
        ax.set_yscale("log")
    ax.set_xticks(range(len(datasets)))
    ax.set_xticklabels(datasets, rotation=30, ha="right", fontsize=8)
    ax.grid(axis="y", alpha=0.3)


def write_png(path, rows):
    """Error and time panels (median, min..max as error bars) for every
    system, and a panel of the SPHERA / reference time ratios."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        log("matplotlib missing (apt-get install python3-matplotlib): no PNG")
        return False
    datasets = [d for d in DATASETS if any(r["dataset"] == d for r in rows)]
    datasets += sorted({r["dataset"] for r in rows} - set(datasets))
    systems = sorted({r["system"] for r in rows}, key=system_order)
    labels = [s for s in systems if s not in REFERENCE_SYSTEMS]
    by_key = {(r["dataset"], r["system"]): r for r in rows}
    colours = dict(zip(labels, COLOURS))
    colours.update({s: REFERENCE_COLOUR for s in REFERENCE_SYSTEMS})

    def series_of(system, key, label, style):
        return (label, style, [bar_value(by_key.get((d, system)), key)
                               for d in datasets])

    panel_width = max(4.0, 0.6 * len(datasets))
    fig, axes = plt.subplots(2, 4, figsize=(4 * panel_width, 9))
    for ax, panel in zip(axes.flat, PNG_BARS):
        if panel is not None:
            key, title, log_scale = panel
            draw_bars(ax, datasets,
                      [series_of(s, key, system_title(s), {"color": colours.get(s)})
                       for s in systems], log_scale)
            ax.set_title(title)
            continue
        # Ratios: no bar (rather than n/a) where there is no reference.
        series = []
        for system in labels:
            for (key, kind), hatch in zip(PNG_RATIOS, ("", "//")):
                label, style, values = series_of(
                    system, key, "%s: %s" % (system_title(system), kind),
                    {"color": colours[system], "hatch": hatch,
                     "edgecolor": "white"})
                values = [v or False for v in values]
                if any(values):
                    series.append((label, style, values))
        draw_bars(ax, datasets, series, False)
        ax.axhline(1.0, color="black", linewidth=0.8)
        ax.set_title("time SPHERA / reference (medians)")
        if series:
            ax.set_ylim(top=ax.get_ylim()[1] * 1.4)  # room for the legend
            ax.legend(fontsize=7, loc="upper left")
        else:
            ax.text(0.5, 0.5, "no reference runs", ha="center",
                    transform=ax.transAxes)
    legend_ax = axes.flat[-1]
    legend_ax.axis("off")
    handles, names = axes.flat[0].get_legend_handles_labels()
    if handles:
        legend_ax.legend(handles, names, loc="upper left", fontsize=9)
    runs = sorted({int(to_float(r.get("runs")) or 0) for r in rows} - {0})
    legend_ax.text(0, 0.4, "bars: median over the successful runs\n"
                   "(%s run(s) per system)\nerror bars: min..max\n"
                   "n/a: no value (failed, skipped or cannot run)" %
                   ("/".join(map(str, runs)) or "1"),
                   fontsize=9, va="top", transform=legend_ax.transAxes)
    fig.suptitle("SPHERA SfM benchmark (COLMAP %s base)" % BASE)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def camera_type(dataset):
    """The camera type a data set's marker stands for in the bound plot."""
    models = DATASET_MODELS.get(dataset, [])
    if len(models) > 1:
        return "hybrid"
    return {"EQUIRECTANGULAR": "equirectangular", "UNIFIED_OMNI": "fisheye 190°",
            "PINHOLE": "perspective"}.get(models[0] if models else "", "other")


BOUND_MARKERS = {"equirectangular": "o", "fisheye 190°": "^", "hybrid": "s",
                 "perspective": "D", "other": "x"}


def write_bound_png(path, runs, summaries):
    """Error against its Cramér-Rao bound: every run as a point (colour:
    system, marker: camera type) for rotation and position, the line of the
    bound; and the medians of error/bound per data set and system as bars
    with their spread."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        log("matplotlib missing (apt-get install python3-matplotlib): no PNG")
        return False
    runs = [r for r in runs if is_ok(r) and to_float(r.get("rot_crb_deg"))]
    summaries = [r for r in summaries if to_float(r.get("rot_crb_ratio"))]
    if not runs:
        return False
    systems = sorted({r["system"] for r in runs} | {r["system"] for r in summaries},
                     key=system_order)
    labels = [s for s in systems if s not in REFERENCE_SYSTEMS]
    colours = dict(zip(labels, COLOURS))
    colours.update({s: REFERENCE_COLOUR for s in REFERENCE_SYSTEMS})
    fig, axes = plt.subplots(2, 2, figsize=(13, 10))
    for ax, (error, bound, title) in zip(axes[0], (
            ("rot_err_mean_deg", "rot_crb_deg", "rotation: mean error (deg)"),
            ("pos_err_mean", "pos_crb", "position: mean error (m)"))):
        values = []
        for system in systems:
            for kind, marker in BOUND_MARKERS.items():
                points = [(to_float(r.get(bound)), to_float(r.get(error)))
                          for r in runs if r["system"] == system
                          and camera_type(r["dataset"]) == kind
                          and to_float(r.get(bound)) and to_float(r.get(error))]
                if not points:
                    continue
                values += [v for p in points for v in p]
                ax.scatter(*zip(*points), marker=marker, s=28, alpha=0.75,
                           facecolors="none" if system in REFERENCE_SYSTEMS
                           else colours[system], edgecolors=colours[system],
                           label="%s, %s" % (system_title(system), kind))
        if values:
            low, high = min(values) / 1.5, max(values) * 1.5
            for factor, style in ((1, "-"), (2, "--")):
                ax.plot([low, high], [factor * low, factor * high], style,
                        color="black", linewidth=0.8,
                        label="error = bound" if factor == 1 else "error = 2 x bound")
            ax.set_xscale("log")
            ax.set_yscale("log")
        ax.set_xlabel("expected mean error at the Cramér-Rao bound")
        ax.set_ylabel("measured")
        ax.set_title(title)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    datasets = [d for d in DATASETS if any(r["dataset"] == d for r in summaries)]
    by_key = {(r["dataset"], r["system"]): r for r in summaries}
    for ax, key, title in ((axes[1][0], "rot_crb_ratio", "rotation error / bound"),
                           (axes[1][1], "pos_crb_ratio", "position error / bound")):
        draw_bars(ax, datasets,
                  [(system_title(s), {"color": colours[s]},
                    [bar_value(by_key.get((d, s)), key) for d in datasets])
                   for s in systems], False)
        ax.axhline(1.0, color="black", linewidth=0.8)
        ax.set_title(title + " (median, min..max)")
        ax.legend(fontsize=7)
    fig.suptitle("Errors against the Cramér-Rao bound of each run's own tracks "
                 "(centres alignment)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def make_parser():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", default="",
                        help="comma-separated data sets (default: all)")
    parser.add_argument("--quick", action="store_true",
                        help="smaller renders (supersample 2, cached separately)")
    parser.add_argument("--repeats", type=int, default=1,
                        help="runs per data set and system (default %(default)s)")
    parser.add_argument("--vary_seed", action="store_true",
                        help="run k uses random seed k-1 (default: COLMAP's "
                             "fixed seed 0 in every run)")
    parser.add_argument("--no_upstream", "--no_reference", dest="no_upstream",
                        action="store_true",
                        help="no runs of upstream COLMAP (and no build of it)")
    parser.add_argument("--no_stock", dest="no_upstream", action="store_true",
                        help=argparse.SUPPRESS)  # its former name
    parser.add_argument("--mapper_options", default="",
                        help="extra options of SPHERA's mapper (not the "
                             "reference's), e.g. \"--Mapper.ba_sphere_residual PIXEL\"")
    parser.add_argument("--variant", action="append", default=[],
                        metavar="NAME=OPTIONS",
                        help="after every SPHERA run, SPHERA's mapper again "
                             "with these extra options on the same database "
                             "(same matches, same seed): rows NAME, e.g. "
                             "\"pixel=--Mapper.ba_sphere_residual PIXEL\"; "
                             "may be repeated")
    parser.add_argument("--variant_only", default="",
                        help="comma-separated data sets that get the "
                             "variants (default: all selected)")
    parser.add_argument("--reuse_extraction", action="store_true",
                        help="extract features once per data set and system "
                             "and start the later runs from a copy of that "
                             "database (their extraction time is the first "
                             "run's); extraction does not depend on the seed")
    parser.add_argument("--label", default=DEFAULT_LABEL,
                        help="system name of SPHERA's rows (default %(default)s)")
    parser.add_argument("--output_dir", default=None,
                        help="default: build/bench")
    parser.add_argument("--colmap", default=None,
                        help="SPHERA's program (default: build/bin/colmap)")
    parser.add_argument("--render", default=None,
                        help="default: build/synthetic/sphera_render")
    parser.add_argument("--upstream_colmap", default=UPSTREAM_COLMAP,
                        help="unpatched upstream COLMAP 4.x, the reference "
                             "(default %(default)s)")
    parser.add_argument("--data_dir", default=SHARED_DATA_DIR,
                        help="shared real data (strecha/, equirect_flat/)")
    parser.add_argument("--wait_minutes", type=float, default=0,
                        help="wait up to this long for SPHERA's colmap and "
                             "sphera_render to appear (polls every 60 s)")
    parser.add_argument("--step_timeout", type=int, default=DEFAULT_STEP_TIMEOUT,
                        help="seconds allowed per command (default %(default)s)")
    parser.add_argument("--fresh", action="store_true",
                        help="do not keep earlier rows in the CSVs")
    parser.add_argument("--list", action="store_true", help="list the data sets")
    return parser


def main():
    parser = make_parser()
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error("--repeats must be at least 1")
    if (not re.fullmatch(r"[A-Za-z0-9_.+-]+", args.label)
            or args.label in REFERENCE_SYSTEMS):
        parser.error("--label: letters, digits and _.+- only, not %s" %
                     " or ".join(sorted(REFERENCE_SYSTEMS)))
    names = [args.label]
    for text in args.variant:
        name = text.partition("=")[0].strip()
        if ("=" not in text or not re.fullmatch(r"[A-Za-z0-9_.+-]+", name)
                or name in names or name in REFERENCE_SYSTEMS):
            parser.error("--variant %r: NAME=OPTIONS with a new NAME of "
                         "letters, digits and _.+-" % text)
        names.append(name)
    try:
        bench = Benchmark(args)
    except ValueError as error:
        parser.error("--mapper_options or --variant: %s" % error)

    if args.list:
        for name in DATASETS:
            unknown = unknown_models(name)
            print(name + ("  (SPHERA and %s)" % bench.reference if not unknown else
                          "  (SPHERA only: %s unknown to %s)" %
                          ("/".join(unknown), bench.reference)))
        return 0
    selected = [n.strip() for n in args.only.split(",") if n.strip()] or DATASETS
    unknown = [n for n in selected if n not in DATASETS]
    if unknown:
        parser.error("unknown data set(s) %s; known: %s" %
                     (", ".join(unknown), ", ".join(DATASETS)))

    os.makedirs(bench.output_dir, exist_ok=True)
    if not bench.wait_for(bench.colmap, "SPHERA colmap"):
        print("benchmark_sfm: %s not found; build it with %s "
              "(or pass --colmap, --wait_minutes)" %
              (bench.colmap, BUILD_HINT), file=sys.stderr)
        return 1
    log("base %s: %s (label %s%s) against %s (%s)" % (
        BASE, bench.colmap, bench.label,
        ", mapper options " + args.mapper_options if args.mapper_options else "",
        REFERENCE_TITLE,
        "not run" if args.no_upstream else bench.reference_colmap))

    try:
        commands = subprocess.run([bench.colmap, "help"], capture_output=True,
                                  text=True, timeout=60).stdout
    except (OSError, subprocess.TimeoutExpired):
        commands = ""
    for command in ("model_evaluator", "strecha_importer"):
        if command not in commands:
            log("warning: %s has no '%s' command; the steps that need it will "
                "fail" % (bench.colmap, command))

    runs, rows = [], []
    for dataset in selected:
        dataset_runs, dataset_rows = bench.run_dataset(dataset)
        runs += dataset_runs
        rows += dataset_rows

    csv_path = os.path.join(bench.output_dir, "sfm_results.csv")
    runs_path = os.path.join(bench.output_dir, "runs.csv")
    png_path = os.path.join(bench.output_dir, "sfm_results.png")
    all_rows, kept = merge_earlier(csv_path, rows, args.fresh)
    add_ratios(all_rows)
    write_csv(csv_path, all_rows, COLUMNS)
    all_runs, kept_runs = merge_earlier(runs_path, runs, args.fresh)
    write_csv(runs_path, all_runs, RUN_COLUMNS)
    print()
    print_table(sort_rows(rows), bench.reference)
    print("\nwrote %s%s" % (csv_path, " (also %d row(s) of earlier runs)" % kept
                            if kept else ""))
    print("wrote %s%s" % (runs_path, " (also %d row(s) of earlier runs)" % kept_runs
                          if kept_runs else ""))
    if write_png(png_path, all_rows):
        print("wrote " + png_path)
    bound_path = os.path.join(bench.output_dir, "sfm_bound.png")
    if write_bound_png(bound_path, all_runs, all_rows):
        print("wrote " + bound_path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
