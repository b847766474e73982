#!/usr/bin/python3
"""Which camera model describes real lenses: every model fitted to the
checkerboard corners of three real cameras (OCamCalib's sample sets in
../shared/data/real_cameras/ocamcalib/: a 190° fisheye, one Ladybug lens, a
paracatadioptric camera), board poses and intrinsics by least squares on the
pixel reprojection error (`sphera_lens_fit`, estimators/lens_fit.h).

Usage (from the repository root, after the standalone libraries are built):
  scripts/fit_real_lenses.py [--lens_fit PATH] [--output DIR]
                             [--models EUCM,DOUBLE_SPHERE,...]
Default program build/estimators/sphera_lens_fit, output build/bench/lenses/:
lenses.csv (set, model, RMS and max error in pixels, corners not visible to
the model, status, params) and lenses.png (RMS per model and lens); the table
is printed. Models the program does not know are skipped with a message.

Corner conventions of corners.mat (checked against the images by refining
each stored corner to the saddle point of the image intensity): the values are
MATLAB pixel coordinates, 1-based (the centre of the upper-left pixel is
(1, 1)). gridInfo.x holds (column; row) per corner; the Mei set's Xp_abs is
the row and Yp_abs the column (OCamCalib's order). COLMAP's pixel is
(column - 0.5, row - 0.5). Board points: gridInfo.X (millimetres); the Mei
set stores none, its 48 corners are 6 rows of 8 in storage order, on a grid
of unit squares (the square size does not change a reprojection error).
"""

import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sphera_common import REPO_ROOT, SHARED_DATA_DIR  # noqa: E402

OCAMCALIB_DIR = os.path.join(SHARED_DATA_DIR, "real_cameras", "ocamcalib")
# (set, image width, height, what it is, image file of corner set i (from
# 0), radius of the image circle in pixels or 0 where the frame crops none)
SETS = [
    ("fisheye190", 752, 480, "190° fisheye", "Fisheye190deg%d.jpg", 290),
    ("ladybug", 1024, 768, "Ladybug lens", "Ladybug%d.jpg", 0),
    ("mei_paracatadioptric", 1280, 1024, "paracatadioptric",
     "imgMei_%03d.jpg", 0),
]
MODELS = ["EUCM", "DOUBLE_SPHERE", "UNIFIED_OMNI", "OPENCV_FISHEYE",
          "THIN_PRISM_FISHEYE", "OCAM",
          "PINHOLE", "OPENCV"]
MEI_GRID = (6, 8)  # rows, columns of the Mei set's corners
# MATLAB's 1-based pixel centres to COLMAP's (upper-left pixel at 0.5).
MATLAB_TO_COLMAP = -0.5
STEP_TIMEOUT = 600
# Corner refinement on the images (the "refined" corners).
REFINE_SIGMA = 1.2
REFINE_RADIUS = 3
REFINE_MAX_SHIFT = 1.5
# "stored": the corners of corners.mat as they are; "refined": each moved to
# the saddle point of its image (refine_corners).
CORNER_VARIANTS = ("stored", "refined")


def read_corners(name):
    """[(image_index, X, Y, Z, px, py)] in COLMAP's pixel convention."""
    import numpy as np
    import scipy.io
    mat = scipy.io.loadmat(os.path.join(OCAMCALIB_DIR, name, "corners.mat"))
    rows = []
    if "gridInfo" in mat:
        grid = mat["gridInfo"][0, 0]
        for image in range(grid["x"].shape[1]):
            x = np.asarray(grid["x"][0, image], float)  # (column; row)
            board = np.asarray(grid["X"][0, image], float)
            for k in range(x.shape[1]):
                rows.append((image, board[0, k], board[1, k], board[2, k],
                             x[0, k] + MATLAB_TO_COLMAP,
                             x[1, k] + MATLAB_TO_COLMAP))
    else:
        row_coord = mat["Xp_abs"][:, 0, :]
        col_coord = mat["Yp_abs"][:, 0, :]
        num_rows, num_cols = MEI_GRID
        assert row_coord.shape[0] == num_rows * num_cols
        for image in range(row_coord.shape[1]):
            for k in range(row_coord.shape[0]):
                rows.append((image, float(k % num_cols), float(k // num_cols),
                             0.0, col_coord[k, image] + MATLAB_TO_COLMAP,
                             row_coord[k, image] + MATLAB_TO_COLMAP))
    return rows


def saddle_point(image, x, y, radius):
    """The saddle point of the (smoothed) intensity nearest to (x, y), in
    pixel-index coordinates (the upper-left pixel's centre is (0, 0)): a
    quadratic fitted to the (2 radius + 1)^2 pixels around the nearest pixel,
    re-centred until it stops moving. None without a saddle there."""
    import numpy as np
    offsets = np.arange(-radius, radius + 1)
    dy, dx = np.meshgrid(offsets, offsets, indexing="ij")
    dx, dy = dx.ravel().astype(float), dy.ravel().astype(float)
    design = np.c_[dx * dx, dx * dy, dy * dy, dx, dy, np.ones_like(dx)]
    for _ in range(10):
        col, row = int(round(x)), int(round(y))
        if (col - radius < 0 or row - radius < 0 or
                col + radius >= image.shape[1] or
                row + radius >= image.shape[0]):
            return None
        patch = image[row - radius:row + radius + 1,
                      col - radius:col + radius + 1].ravel()
        a, b, c, d, e, _ = np.linalg.lstsq(design, patch, rcond=None)[0]
        hessian = np.array([[2 * a, b], [b, 2 * c]])
        if np.linalg.det(hessian) >= 0:
            return None  # an extremum, not a saddle
        step = np.linalg.solve(hessian, [-d, -e])
        if np.abs(step).max() > radius:
            return None
        new_x, new_y = col + step[0], row + step[1]
        if abs(new_x - x) < 1e-3 and abs(new_y - y) < 1e-3:
            return new_x, new_y
        x, y = new_x, new_y
    return x, y


def refine_corners(name, image_pattern, rows):
    """The corners moved to the saddle point of their image's intensity
    (Gaussian-smoothed, sigma REFINE_SIGMA px, window of REFINE_RADIUS px);
    a corner without a saddle within REFINE_MAX_SHIFT px is dropped. Returns
    the kept rows and the number dropped."""
    import numpy as np
    from PIL import Image
    from scipy import ndimage
    images = {}
    kept = []
    for row in rows:
        index = row[0]
        if index not in images:
            path = os.path.join(OCAMCALIB_DIR, name, image_pattern % (index + 1))
            grey = np.asarray(Image.open(path).convert("L"), float)
            images[index] = ndimage.gaussian_filter(grey, REFINE_SIGMA)
        # COLMAP pixels to pixel-index coordinates: -0.5.
        x, y = row[4] - 0.5, row[5] - 0.5
        saddle = saddle_point(images[index], x, y, REFINE_RADIUS)
        if saddle is None or math.hypot(saddle[0] - x,
                                        saddle[1] - y) > REFINE_MAX_SHIFT:
            continue
        kept.append(row[:4] + (saddle[0] + 0.5, saddle[1] + 0.5))
    return kept, len(rows) - len(kept)


def write_corner_file(path, width, height, rows):
    with open(path, "w") as f:
        f.write("# width height, then image_index board_x board_y board_z "
                "pixel_x pixel_y (COLMAP pixels)\n")
        f.write("%d %d\n" % (width, height))
        for r in rows:
            f.write("%d %.6f %.6f %.6f %.6f %.6f\n" % r)


def known_models(program, absent_file, models):
    """The models the program accepts: it names an unknown model before it
    opens the (absent) corner file."""
    known = []
    for model in models:
        done = subprocess.run([program, absent_file, model],
                              capture_output=True, text=True)
        if "unknown camera model name" in done.stderr:
            print("  skipped %s: not a model of this build" % model)
        else:
            known.append(model)
    return known


def fit(program, corner_file, models, circle_radius):
    """Parses the program's "key value" blocks into dicts."""
    command = [program]
    if circle_radius > 0:
        command += ["--circle_radius", str(circle_radius)]
    done = subprocess.run(command + [corner_file] + models,
                          capture_output=True, text=True,
                          timeout=STEP_TIMEOUT)
    if done.returncode != 0:
        raise RuntimeError("%s failed: %s" % (program, done.stderr.strip()))
    results, current = [], {}
    for line in done.stdout.splitlines():
        if not line.strip():
            if current:
                results.append(current)
            current = {}
            continue
        key, _, value = line.partition(" ")
        current[key] = value
    if current:
        results.append(current)
    return results


def write_csv(path, rows, keys):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)


def print_table(rows, keys):
    widths = [max(len(k), *(len(str(r.get(k, ""))) for r in rows))
              for k in keys]
    print("  ".join(k.ljust(w) for k, w in zip(keys, widths)))
    for r in rows:
        print("  ".join(str(r.get(k, "")).ljust(w)
                        for k, w in zip(keys, widths)))


def plot(path, rows, models):
    """RMS per model and lens, one panel per corner variant."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    fig, axes = plt.subplots(1, len(CORNER_VARIANTS), figsize=(13, 4.6),
                             sharey=True)
    width = 0.8 / len(models)
    for ax, variant in zip(axes, CORNER_VARIANTS):
        for m, model in enumerate(models):
            values = []
            for name, *_ in SETS:
                match = [r for r in rows if r["set"] == name and
                         r["model"] == model and r["corners"] == variant]
                values.append(float(match[0]["rms_px"]) if match else np.nan)
            xs = np.arange(len(SETS)) + (m - (len(models) - 1) / 2) * width
            ax.bar(xs, values, width, label=model)
        ax.axhline(0.5, color="grey", lw=0.8, ls="--")
        ax.set_yscale("log")
        ax.set_ylim(0.1, 50)
        ax.set_xticks(np.arange(len(SETS)))
        ax.set_xticklabels(["%s\n%s" % (s[0], s[3]) for s in SETS],
                           fontsize=8)
        ax.set_title("%s corners" % variant)
    axes[0].set_ylabel("reprojection RMS [px] (log; dashed: 0.5 px)")
    axes[-1].legend(fontsize=7, ncol=2)
    fig.suptitle("Camera models fitted to real checkerboard corners "
                 "(OCamCalib sample sets)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--lens_fit", default=os.path.join(
        REPO_ROOT, "build", "estimators", "sphera_lens_fit"))
    ap.add_argument("--output", default=os.path.join(REPO_ROOT, "build",
                                                     "bench", "lenses"))
    ap.add_argument("--models", default=",".join(MODELS))
    args = ap.parse_args()
    if not os.path.isdir(OCAMCALIB_DIR):
        print("skipped: %s is absent" % OCAMCALIB_DIR)
        return 0
    if not os.access(args.lens_fit, os.X_OK):
        print("error: %s is not built (ninja sphera_lens_fit_main)"
              % args.lens_fit, file=sys.stderr)
        return 1
    os.makedirs(args.output, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        models = known_models(args.lens_fit, os.path.join(tmp, "absent.txt"),
                              args.models.split(","))
        for name, width, height, _, image_pattern, circle_radius in SETS:
            stored = read_corners(name)
            refined, dropped = refine_corners(name, image_pattern, stored)
            print("%s: %d corners in %d images; refined on the images: %d "
                  "kept, %d without a saddle point within %.1f px dropped"
                  % (name, len(stored), len({c[0] for c in stored}),
                     len(refined), dropped, REFINE_MAX_SHIFT), flush=True)
            for variant, corners in zip(CORNER_VARIANTS, (stored, refined)):
                corner_file = os.path.join(tmp, "%s_%s.txt" % (name, variant))
                write_corner_file(corner_file, width, height, corners)
                for result in fit(args.lens_fit, corner_file, models,
                                  circle_radius):
                    rows.append({
                        "set": name, "corners": variant,
                        "model": result["model"],
                        "rms_px": "%.3f" % float(result["rms_px"]),
                        "max_px": "%.2f" % float(result["max_px"]),
                        "num_corners": result["num_observations"],
                        "not_visible": result["num_not_visible"],
                        "corner_angle_deg": result["max_corner_angle_deg"],
                        "circle_angle_deg": result.get("circle_angle_deg",
                                                       ""),
                        "status": result["status"],
                        "params": result["params"].replace(",", " "),
                        "image_rms_px": result["image_rms_px"].replace(
                            ",", " "),
                        "message": result.get("message", "")})
    keys = ["set", "corners", "model", "rms_px", "max_px", "num_corners",
            "not_visible", "corner_angle_deg", "circle_angle_deg", "status"]
    print()
    print_table(rows, keys)
    print("\nparams (each model's order, camera_models/registry.h)")
    print_table(rows, ["set", "corners", "model", "params"])
    write_csv(os.path.join(args.output, "lenses.csv"), rows,
              keys + ["params", "image_rms_px", "message"])
    plot(os.path.join(args.output, "lenses.png"), rows, models)
    print("\nwrote %s and %s" % (os.path.join(args.output, "lenses.csv"),
                                 os.path.join(args.output, "lenses.png")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
