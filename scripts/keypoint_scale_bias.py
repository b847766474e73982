#!/usr/bin/env python3
"""Radial bias of keypoints by their scale: does a model's bundle adjustment
see the large keypoints shifted towards or away from the image centre?

For every observation of a model, the reprojection residual (keypoint minus
projected 3D point, pixels) is split into its radial part (along the
direction from the principal point: positive outwards) and binned by the
keypoint's radius from the principal point and its scale (the square root
of the determinant of its affine shape in the database; SIFT's sigma in
pixels). A mean radial residual that changes with scale is a bias the
adjustment cannot model: it treats every keypoint alike, so it fits a focal
length and distortion to the average and the lens offsets of a rig follow
the focal length (a lens moved back along its axis by d looks like a focal
length longer by d / depth). A light fall-off towards the rim (vignetting)
does this: a blob on a brightness slope is found off its centre, towards
the brighter side, the more the larger the blob.

Usage (from the repository root):
  scripts/keypoint_scale_bias.py --model SPARSE/0 --database DB.db \\
      [--output_dir DIR] [--label NAME]
prints the table and writes DIR/scale_bias.csv and DIR/scale_bias.png
(default DIR: the model's folder). The model may be binary or text, of any
camera model but EQUIRECTANGULAR (the projections of scripts/cramer_rao.py)."""
import argparse
import csv
import os
import sqlite3
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cramer_rao  # noqa: E402
import sphera_common as common  # noqa: E402

RADIUS_BINS = [0, 150, 300, 400, 450, 500, 600, 800, 1200, 2000, 4000]
SCALE_BINS = [0, 2, 4, 8, 16, 1e9]
MIN_COUNT = 20


def project(model, params, X):
    """Pixels (N x 2) of camera-frame points X (N x 3) through the camera
    (cramer_rao.project, which follows camera_models/), and the principal
    point: the pixel of the optical axis."""
    if model == "EQUIRECTANGULAR":
        raise SystemExit("keypoint_scale_bias: camera model EQUIRECTANGULAR "
                         "has no principal point to measure radii from")
    camera = (model, 0, 0, list(params))
    try:
        with np.errstate(invalid="ignore", divide="ignore"):
            uv = cramer_rao.project(camera, np.asarray(X, dtype=float))
            centre = cramer_rao.project(camera, np.array([[0.0, 0.0, 1.0]]))
    except ValueError as error:
        raise SystemExit(f"keypoint_scale_bias: {error}") from None
    return uv, (float(centre[0, 0]), float(centre[0, 1]))


def keypoint_scales(database):
    """{image name: scales (N) of its keypoints}."""
    con = sqlite3.connect(f"file:{database}?mode=ro", uri=True)
    names = dict(con.execute("SELECT image_id, name FROM images"))
    scales = {}
    for image_id, rows, cols, data in con.execute(
            "SELECT image_id, rows, cols, data FROM keypoints"):
        if not rows or image_id not in names:
            continue
        a = np.frombuffer(data, dtype=np.float32).reshape(rows, cols)
        if cols >= 6:
            scales[names[image_id]] = np.sqrt(np.abs(
                a[:, 2] * a[:, 5] - a[:, 3] * a[:, 4]))
        elif cols == 4:
            scales[names[image_id]] = a[:, 2]
        else:
            raise SystemExit(f"keypoint_scale_bias: {database}: keypoints "
                             f"of {names[image_id]} have no scale ({cols} "
                             "columns)")
    return scales


def observations(model_text, database):
    """Array (N x 3): radius from the principal point, keypoint scale,
    radial residual (outwards positive), over every observation."""
    cameras, images, points = common.read_text_model(model_text)
    xyz = {pid: np.array(p[0]) for pid, p in points.items()}
    scales = keypoint_scales(database)
    rows = []
    for fields, obs in images.values():
        name = fields[9]
        if name not in scales:
            raise SystemExit(f"keypoint_scale_bias: image {name} of the "
                             f"model has no keypoints in {database}")
        model, _, _, params = cameras[int(fields[8])]
        q = [float(v) for v in fields[1:5]]
        t = np.array([float(v) for v in fields[5:8]])
        R = common.rotation_from_quaternion(*q)
        idx = [k for k, (_, _, pid) in enumerate(obs) if pid != -1]
        if not idx:
            continue
        uv = np.array([obs[k][:2] for k in idx])
        X = np.array([xyz[obs[k][2]] for k in idx]) @ R.T + t
        projected, (cx, cy) = project(model, params, X)
        d = uv - projected
        rel = uv - np.array([cx, cy])
        radius = np.hypot(rel[:, 0], rel[:, 1])
        with np.errstate(invalid="ignore", divide="ignore"):
            radial = (d * rel).sum(axis=1) / radius
        rows.append(np.stack([radius, scales[name][idx], radial], axis=1))
    out = np.concatenate(rows)
    return out[np.isfinite(out).all(axis=1)]


def binned(obs):
    """[(radius bin, scale bin, count, mean radial residual)]."""
    cells = []
    for i in range(len(RADIUS_BINS) - 1):
        in_r = (obs[:, 0] >= RADIUS_BINS[i]) & (obs[:, 0] < RADIUS_BINS[i + 1])
        if in_r.sum() < MIN_COUNT:
            continue
        for j in range(len(SCALE_BINS) - 1):
            m = in_r & (obs[:, 1] >= SCALE_BINS[j]) & (
                obs[:, 1] < SCALE_BINS[j + 1])
            count = int(m.sum())
            cells.append((i, j, count,
                          float(obs[m, 2].mean()) if count >= MIN_COUNT
                          else float("nan")))
    return cells


def scale_name(j):
    hi = SCALE_BINS[j + 1]
    return f"{SCALE_BINS[j]:g}+ px" if hi >= 1e9 else \
        f"{SCALE_BINS[j]:g}-{hi:g} px"


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    parser.add_argument("--model", required=True)
    parser.add_argument("--database", required=True)
    parser.add_argument("--output_dir", default="")
    parser.add_argument("--label", default="")
    parser.add_argument("--colmap", default=os.path.join(
        common.REPO_ROOT, "build", "bin", "colmap"),
        help="converts a binary model to text")
    args = parser.parse_args()
    common.COLMAP = args.colmap
    for path in (args.model, args.database):
        if not os.path.exists(path):
            raise SystemExit(f"keypoint_scale_bias: {path} does not exist")
    model_text = args.model
    if os.path.exists(os.path.join(args.model, "images.bin")):
        model_text = os.path.join(tempfile.mkdtemp(prefix="scale_bias_"),
                                  "text")
        common.model_to_text(args.model, model_text)
    obs = observations(model_text, args.database)
    cells = binned(obs)
    label = args.label or args.model
    print(f"{label}: {len(obs)} observations; mean radial residual "
          "(keypoint minus projection, px, outwards positive) by radius "
          "from the principal point and keypoint scale (count)")
    header = ["radius, px"] + [scale_name(j) for j in range(len(SCALE_BINS) - 1)]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for i in sorted({c[0] for c in cells}):
        row = [f"{RADIUS_BINS[i]}-{RADIUS_BINS[i + 1]}"]
        for _, j, count, mean in (c for c in cells if c[0] == i):
            row.append(f"{mean:+.3f} ({count})" if count >= MIN_COUNT
                       else f"- ({count})")
        print("| " + " | ".join(row) + " |")
    out_dir = args.output_dir or args.model
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "scale_bias.csv"), "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["label", "radius_min_px", "radius_max_px",
                         "scale_min_px", "scale_max_px", "count",
                         "mean_radial_residual_px"])
        for i, j, count, mean in cells:
            writer.writerow([label, RADIUS_BINS[i], RADIUS_BINS[i + 1],
                             SCALE_BINS[j], SCALE_BINS[j + 1], count, mean])
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    for j in range(len(SCALE_BINS) - 1):
        pts = [((RADIUS_BINS[i] + RADIUS_BINS[i + 1]) / 2, mean)
               for i, jj, count, mean in cells
               if jj == j and count >= MIN_COUNT]
        if pts:
            ax.plot(*zip(*pts), marker="o", label=scale_name(j))
    ax.axhline(0, color="grey", linewidth=0.5)
    ax.set_xlabel("radius from the principal point, px")
    ax.set_ylabel("mean radial residual, px (outwards +)")
    ax.set_title(f"keypoint scale bias: {os.path.basename(label)}")
    ax.legend(title="keypoint scale")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "scale_bias.png"), dpi=100)
    print(f"wrote {os.path.join(out_dir, 'scale_bias.csv')} and "
          "scale_bias.png")


if __name__ == "__main__":
    main()
