#!/usr/bin/python3
"""Bundle adjustment benchmark of SPHERA (paper: Gava & Stricker 2015, Table 1
and Fig. 5), without SfM: the ground-truth model of a rendered scene with its
exact observations gets pixel noise, outliers and perturbed poses/points, and
is refined by `colmap sphere_bundle_adjuster` in each mode:

  full BA, angular residual      --mode full --residual angular
  full BA, pixel residual        --mode full --residual pixel
  camera-only BA, tau 1..5 px    --mode camera_only --tau_px T

Each result is scored by `colmap model_evaluator` against the ground truth
(orientation, position, mean reprojection error, 3D point error vs depth).

Usage (from the repository root, after scripts/build.sh):
  scripts/benchmark_ba.py                 full run (renders cached)
  scripts/benchmark_ba.py --quick         fewer points, faster
Options: --output DIR (default build/bench), --colmap, --render, --wait S
(poll `colmap help` for sphere_bundle_adjuster up to S seconds), --seed.

Experiments (--only a,b,...; default all):
  table1          paper Table 1 (each residual, each BA mode) and the Fig. 5
                  tau sweep on the room with 9 panoramas
  timing          camera-only vs full BA as the number of points grows
  poles           angular vs pixel residual, cameras near floor and ceiling
  fig9            paper Fig. 9 with ground truth: hybrid vs spherical-only vs
                  perspective-only subsets of one rendered set, and PINHOLE
                  focal length recovery in the hybrid set
  residual_types  angular vs pixel residual per camera type (synthetic noise)
  sift_residuals  angular vs pixel residual on real SIFT keypoints: the
                  mapper's models of benchmark_sfm.py's rendered sets

Outputs under OUTPUT/ba/: table1.csv, tau_sweep.csv, timing.csv, poles.csv,
fig9.csv, residual_types.csv, sift_residuals.csv and the PNGs
fig5_tau_sweep.png, timing.png, fig9.png, residual_types.png,
sift_residuals.png; tables are printed. Scenes are rendered once into
OUTPUT/ba/scenes/ (sphera_render --supersample 1; sift_residuals: OUTPUT/ba/
sfm/scenes/, supersample 2) and reused.

Protocol: noise sigma 0.5 px on every observation, 5% outlier observations
(offset 20-60 px), poses perturbed by 0.3 deg / 2 cm, points by 2 cm. The full
BAs use a Cauchy loss (1 px) because of the outliers; the camera-only BA
starts with tau = 8 px for 5 iterations (the perturbation alone is ~2 px),
then runs at the swept tau (time of both stages reported).
"""

import argparse
import csv
import json
import math
import os
import random
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_sfm  # noqa: E402  (the SfM pipeline)
from sphera_common import (REPO_ROOT, poles_rig, quat_mul,  # noqa: E402
                           quat_rotate, read_text_cameras, read_text_images,
                           read_text_rows, run_logged, run_render, write_rig)

# Seconds allowed per command.
STEP_TIMEOUT = 3600


# ---------------------------------------------------------------------------
# COLMAP text model I/O
# ---------------------------------------------------------------------------
def read_model(path):
    """(cameras {id: (model, width, height, params)}, images {id: {"q", "t",
    "camera_id", "name", "points2D": [[x, y, point3D_id]]}}, points {id:
    {"xyz", "rgb" (text), "track"}}) of a text model, in the form that
    perturb() changes and write_model() writes."""
    images = {}
    for image_id, (e, obs) in read_text_images(path).items():
        images[image_id] = {
            "q": [float(x) for x in e[1:5]], "t": [float(x) for x in e[5:8]],
            "camera_id": int(e[8]), "name": e[9],
            "points2D": [list(o) for o in obs]}
    points = {}
    for e in read_text_rows(os.path.join(path, "points3D.txt")):
        track = [(int(e[k]), int(e[k + 1])) for k in range(8, len(e), 2)]
        points[int(e[0])] = {"xyz": [float(x) for x in e[1:4]],
                             "rgb": e[4:7], "track": track}
    return read_text_cameras(path), images, points


def write_model(path, cameras, images, points):
    os.makedirs(path, exist_ok=True)
    with open(os.path.join(path, "cameras.txt"), "w") as f:
        for cid, (model, w, h, params) in sorted(cameras.items()):
            f.write("%d %s %d %d %s\n" % (cid, model, w, h,
                                          " ".join(repr(p) for p in params)))
    with open(os.path.join(path, "images.txt"), "w") as f:
        for iid, im in sorted(images.items()):
            f.write("%d %s %s %d %s\n" % (
                iid, " ".join(repr(x) for x in im["q"]),
                " ".join(repr(x) for x in im["t"]), im["camera_id"],
                im["name"]))
            f.write(" ".join("%r %r %d" % (p[0], p[1], p[2])
                             for p in im["points2D"]) + "\n")
    with open(os.path.join(path, "points3D.txt"), "w") as f:
        for pid, p in sorted(points.items()):
            f.write("%d %s %s 0 %s\n" % (
                pid, " ".join(repr(x) for x in p["xyz"]), " ".join(p["rgb"]),
                " ".join("%d %d" % t for t in p["track"])))


# ---------------------------------------------------------------------------
def random_unit(rng):
    while True:
        v = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in v))
        if n > 1e-6:
            return [x / n for x in v]


def perturb(gt, rng, sigma_px, outlier_rate, rot_deg, pos_m, point_m,
            keep_points=None):
    cameras, images, points = gt
    images = json.loads(json.dumps(images))
    images = {int(k): v for k, v in images.items()}
    points = {pid: dict(p) for pid, p in points.items()
              if keep_points is None or pid in keep_points}
    for iid, im in images.items():
        model, w, h, params = cameras[im["camera_id"]]
        for p in im["points2D"]:
            if p[2] not in points:
                p[2] = -1
            p[0] += rng.gauss(0, sigma_px)
            p[1] += rng.gauss(0, sigma_px)
            if rng.random() < outlier_rate:
                a = rng.uniform(0, 2 * math.pi)
                r = rng.uniform(20, 60)
                p[0] += r * math.cos(a)
                p[1] += r * math.sin(a)
            if model == "EQUIRECTANGULAR":
                p[0] %= w
                p[1] = min(max(p[1], 0.0), h - 1e-6)
            else:
                p[0] = min(max(p[0], 0.0), w - 1e-6)
                p[1] = min(max(p[1], 0.0), h - 1e-6)
        # Centre C = -R^T t; perturb rotation and centre.
        q = im["q"]
        qi = [q[0], -q[1], -q[2], -q[3]]
        c = [-x for x in quat_rotate(qi, im["t"])]
        axis = random_unit(rng)
        ang = math.radians(rot_deg)
        dq = [math.cos(ang / 2)] + [math.sin(ang / 2) * a for a in axis]
        q2 = quat_mul(dq, q)
        c2 = [c[k] + pos_m * d for k, d in enumerate(random_unit(rng))]
        im["q"] = q2
        im["t"] = [-x for x in quat_rotate(q2, c2)]
    for pid, p in points.items():
        d = random_unit(rng)
        p["xyz"] = [p["xyz"][k] + point_m * d[k] for k in range(3)]
    return cameras, images, points


# ---------------------------------------------------------------------------
def wait_for_command(colmap, wait_s):
    t0 = time.time()
    while True:
        if os.path.exists(colmap):
            out = subprocess.run([colmap, "help"], capture_output=True,
                                 text=True).stdout
            if "sphere_bundle_adjuster" in out:
                return True
        if time.time() - t0 > wait_s:
            return False
        print("waiting for sphere_bundle_adjuster in %s help ..." % colmap,
              flush=True)
        time.sleep(30)


def render(args, out_dir, extra):
    if os.path.exists(os.path.join(out_dir, "sparse_gt", "points3D.txt")):
        return
    if os.path.exists(out_dir):
        shutil.rmtree(out_dir)
    print("rendering", out_dir, flush=True)
    run_render(out_dir, "--supersample", "1", "--seed", args.seed, *extra,
               program=args.render)


class Bench:
    def __init__(self, args, root):
        self.args = args
        self.root = root

    def adjust_and_evaluate(self, tag, scene, input_model, mode, residual,
                            tau=None, gt_path=None, extra=(), detail=False,
                            depth_path=None):
        """gt_path, depth_path: default scene/sparse_gt, scene/depth.
        detail: also max rotation error, per camera model reprojection error
        (px equivalents, weighted by observations) and mean rotation /
        position error (rot_deg_MODEL, pos_MODEL), and the output model path
        in row["_model"]."""
        gt_path = gt_path or os.path.join(scene, "sparse_gt")
        a = self.args
        work = os.path.join(self.root, "runs", tag)
        if os.path.exists(work):
            shutil.rmtree(work)
        os.makedirs(work)
        out = os.path.join(work, "model")
        total = 0.0
        base = [a.colmap, "sphere_bundle_adjuster", "--output_path", out]
        if mode == "full":
            rc, dt = run_logged(
                base + ["--input_path", input_model, "--mode", "full",
                        "--residual", residual, "--loss", "cauchy",
                        "--loss_scale_px", "1"] + list(extra),
                os.path.join(work, "ba.log"), STEP_TIMEOUT)
            total += dt
        else:
            stage1 = os.path.join(work, "stage1")
            rc, dt = run_logged(
                [a.colmap, "sphere_bundle_adjuster", "--input_path",
                 input_model, "--output_path", stage1, "--mode",
                 "camera_only", "--tau_px", "8", "--max_iterations",
                 "5"] + list(extra), os.path.join(work, "stage1.log"),
                STEP_TIMEOUT)
            total += dt
            if rc == 0:
                rc, dt = run_logged(
                    base + ["--input_path", stage1, "--mode", "camera_only",
                            "--tau_px", str(tau), "--max_iterations",
                            "20"] + list(extra),
                    os.path.join(work, "ba.log"), STEP_TIMEOUT)
                total += dt
        row = {"run": tag, "mode": mode, "residual": residual,
               "tau_px": "" if tau is None else tau, "status": "ok",
               "time_s": round(total, 3)}
        if rc != 0:
            row["status"] = "ba_failed"
            return row
        ev = os.path.join(work, "eval")
        os.makedirs(ev)
        rc, _ = run_logged([a.colmap, "model_evaluator", "--gt_path",
                            gt_path, "--input_path", out, "--depth_path",
                            depth_path or os.path.join(scene, "depth"),
                            "--output_path", ev],
                           os.path.join(work, "eval.log"), STEP_TIMEOUT)
        if rc != 0:
            row["status"] = "eval_failed"
            return row
        with open(os.path.join(ev, "evaluation.json")) as f:
            e = json.load(f)
        for k in ["mean_rotation_error_deg", "mean_position_error",
                  "mean_angular_error_px", "mean_point_error",
                  "median_point_error", "num_points3D"]:
            row[k] = e.get(k, "")
        if detail:
            row["num_registered"] = e.get("num_registered", "")
            row["max_rotation_error_deg"] = e.get("max_rotation_error_deg", "")
            row["max_position_error"] = e.get("max_position_error", "")
            by_model = {}
            for c in e.get("cameras", []):
                n = c.get("num_observations", 0)
                acc = by_model.setdefault(c["model"], [0, 0.0])
                acc[0] += n
                acc[1] += n * c.get("mean_angular_error_px", 0.0)
            for m, (n, tot) in by_model.items():
                row["reproj_px_" + m] = tot / n if n else ""
            gt_cameras, gt_images, _ = read_model(gt_path)
            model_of = {im["name"]: gt_cameras[im["camera_id"]][0]
                        for im in gt_images.values()}
            pose_by_model = {}
            for im in e.get("images", []):
                if im.get("registered"):
                    pose_by_model.setdefault(model_of[im["name"]], []).append(
                        (im["rotation_error_deg"], im["position_error"]))
            for m, errors in pose_by_model.items():
                row["rot_deg_" + m] = sum(r for r, _ in errors) / len(errors)
                row["pos_" + m] = sum(p for _, p in errors) / len(errors)
            row["_model"] = out
        return row


def write_csv(path, rows):
    keys = []
    for r in rows:
        for k in r:
            if k not in keys and not k.startswith("_"):
                keys.append(k)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)


def fmt(v, p=4):
    if isinstance(v, float):
        return ("%." + str(p) + "g") % v
    return str(v)


def print_table(title, rows, keys):
    print("\n" + title)
    widths = [max(len(k), *(len(fmt(r.get(k, ""))) for r in rows)) for k in keys]
    print("  ".join(k.ljust(w) for k, w in zip(keys, widths)))
    for r in rows:
        print("  ".join(fmt(r.get(k, "")).ljust(w) for k, w in zip(keys, widths)))


def ratio_row(angular, pixel, base):
    """`base` plus pixel/angular ratios of the error columns of two rows."""
    row = dict(base, residual="pixel/angular", status="")
    for k in ("mean_rotation_error_deg", "max_rotation_error_deg",
              "mean_position_error", "mean_point_error",
              "mean_angular_error_px"):
        a, p = angular.get(k), pixel.get(k)
        if isinstance(a, (int, float)) and a > 0 and \
                isinstance(p, (int, float)):
            row[k] = p / a
    return row


# ---------------------------------------------------------------------------
# Fig. 9 (hybrid set) and residual types
# ---------------------------------------------------------------------------
FIG9_FOCAL = 320.0


def yaw_pitch_pose(yaw_deg, pitch_deg, centre):
    """cam_from_world (q, t) of a camera at `centre` whose optical axis is
    turned by yaw about +Y (0 deg: looking along +Z, 90 deg: along +X), then
    pitched about its x axis."""
    a, b = math.radians(yaw_deg), math.radians(pitch_deg)
    q_wc = quat_mul([math.cos(a / 2), 0.0, math.sin(a / 2), 0.0],
                [math.cos(b / 2), math.sin(b / 2), 0.0, 0.0])
    q_cw = [q_wc[0], -q_wc[1], -q_wc[2], -q_wc[3]]
    t = [-x for x in quat_rotate(q_cw, centre)]
    return q_cw, t


def fig9_rig(path):
    """5 upright EQUIRECTANGULAR 1024x512 panoramas (the four corners of a
    2 x 2 m square and its centre) and 6 PINHOLE 640x480 cameras (f = 320,
    90 deg horizontal FOV) between them, on a circle of radius 0.9 m, each
    looking across the room in its own horizontal direction (60 deg apart),
    so that neighbours share a wall region and the six form a closed loop
    (room: x, z in [-2, 2], y in [-1.5, 1.5], +Y down)."""
    panos = [((-1.0, -0.10, -1.0), 0), ((1.0, 0.10, -1.0), 72),
             ((0.0, 0.0, 0.0), 144), ((-1.0, 0.10, 1.0), 216),
             ((1.0, -0.10, 1.0), 288)]
    pins = []
    for k in range(6):
        phi = math.radians(60 * k)
        c = (0.9 * math.sin(phi), 0.15 * (-1) ** k, 0.9 * math.cos(phi))
        pins.append((c, 60 * k + 180 + 25, 5 * (-1) ** k))
    f = FIG9_FOCAL
    with open(path, "w") as out:
        out.write("# NAME MODEL W H PARAMS | QW QX QY QZ TX TY TZ\n")
        for k, (c, yaw) in enumerate(panos):
            q, t = yaw_pitch_pose(yaw, 0.0, c)
            out.write("sph%02d.jpg EQUIRECTANGULAR 1024 512 1024 512 | %s %s\n"
                      % (k, " ".join(repr(x) for x in q),
                         " ".join(repr(x) for x in t)))
        for k, (c, yaw, pitch) in enumerate(pins):
            q, t = yaw_pitch_pose(yaw, pitch, c)
            out.write("pin%02d.jpg PINHOLE 640 480 %r %r 320 240 | %s %s\n"
                      % (k, f, f, " ".join(repr(x) for x in q),
                         " ".join(repr(x) for x in t)))


def subset_model(model, keep_images):
    """The model restricted to `keep_images` (image ids): their observations
    only; points left with < 2 observations are dropped (their 2D points
    keep their index, with point id -1); unused cameras are dropped."""
    cameras, images, points = model
    imgs = {iid: json.loads(json.dumps(images[iid])) for iid in keep_images}
    pts = {}
    for pid, p in points.items():
        track = [tuple(t) for t in p["track"] if t[0] in imgs]
        if len(track) >= 2:
            q = dict(p)
            q["track"] = track
            pts[pid] = q
    for im in imgs.values():
        for o in im["points2D"]:
            if o[2] != -1 and o[2] not in pts:
                o[2] = -1
    cams = {cid: cameras[cid] for cid in
            sorted({im["camera_id"] for im in imgs.values()})}
    return cams, imgs, pts


def model_stats(model):
    cameras, images, points = model
    per_image = [sum(1 for o in im["points2D"] if o[2] != -1)
                 for im in images.values()]
    return {"images": len(images), "points_in": len(points),
            "min_obs_per_image": min(per_image) if per_image else 0}


def run_fig9(args, bench, root, protocol, quick):
    """Paper Fig. 9 with ground truth: hybrid vs spherical-only vs
    perspective-only subsets of one rendered set, full and camera-only BA,
    and focal length recovery on the hybrid set."""
    n_points = 4000 if quick else 8000
    rng = random.Random("fig9-%d" % args.seed)
    rig = os.path.join(root, "fig9_rig.txt")
    fig9_rig(rig)
    scene = os.path.join(root, "scenes", "fig9_%d" % n_points)
    render(args, scene, ["--rig", rig, "--points", str(n_points)])
    gt = read_model(os.path.join(scene, "sparse_gt"))
    # Perturb the whole set once: the subsets share noise and outliers.
    pert = perturb(gt, rng, **protocol)
    by_model = {}
    for iid, im in gt[1].items():
        by_model.setdefault(gt[0][im["camera_id"]][0], set()).add(iid)
    subsets = [("hybrid", set(gt[1])),
               ("spherical", by_model.get("EQUIRECTANGULAR", set())),
               ("perspective", by_model.get("PINHOLE", set()))]
    rows, inputs = [], {}
    for name, keep in subsets:
        gt_path = os.path.join(root, "inputs", "fig9_%s_gt" % name)
        in_path = os.path.join(root, "inputs", "fig9_%s" % name)
        gt_s = subset_model(gt, keep)
        write_model(gt_path, *gt_s)
        in_s = subset_model(pert, keep)
        write_model(in_path, *in_s)
        inputs[name] = (in_path, gt_path, in_s)
        st = model_stats(in_s)
        for mode in ("full", "camera_only"):
            r = bench.adjust_and_evaluate(
                "fig9_%s_%s" % (name, mode), scene, in_path, mode, "angular",
                2 if mode == "camera_only" else None, gt_path=gt_path,
                detail=True)
            row = {"subset": name}
            row.update(st)
            row.update(r)
            rows.append(row)

    # Intrinsics: PINHOLE focal +5% in the input, refined by the full BA.
    intr = []
    for name in ("hybrid", "perspective"):
        in_path, gt_path, in_s = inputs[name]
        cams = {cid: (m, w, h, list(p)) for cid, (m, w, h, p)
                in in_s[0].items()}
        for cid, (m, w, h, p) in cams.items():
            if m == "PINHOLE":
                p[0] *= 1.05
                p[1] *= 1.05
        f_path = in_path + "_f105"
        write_model(f_path, cams, in_s[1], in_s[2])
        for refine in ((0, 1) if name == "hybrid" else (1,)):
            r = bench.adjust_and_evaluate(
                "fig9_%s_f105_refine%d" % (name, refine), scene, f_path,
                "full", "angular", gt_path=gt_path,
                extra=["--refine_intrinsics", str(refine)], detail=True)
            row = {"subset": name, "refine_intrinsics": refine,
                   "f_true": FIG9_FOCAL,
                   "f_input": [p for m, w, h, p in cams.values()
                               if m == "PINHOLE"][0][0]}
            row.update(r)
            if r["status"] == "ok":
                # The adjuster writes binary: convert to text, read cameras.txt.
                txt = r["_model"] + "_txt"
                os.makedirs(txt, exist_ok=True)
                rc, _ = run_logged(
                    [args.colmap, "model_converter", "--input_path",
                     r["_model"], "--output_path", txt, "--output_type",
                     "TXT"],
                    os.path.join(os.path.dirname(txt), "convert.log"),
                    STEP_TIMEOUT)
                out_cams = read_text_cameras(txt) if rc == 0 else {}
                if rc != 0:
                    row["status"] = "convert_failed"
                pin = [p for m, w, h, p in out_cams.values() if m == "PINHOLE"]
                if pin:
                    row["fx_out"], row["fy_out"] = pin[0][0], pin[0][1]
                    row["cx_out"], row["cy_out"] = pin[0][2], pin[0][3]
                    row["f_rel_error"] = (0.5 * (pin[0][0] + pin[0][1]) -
                                          FIG9_FOCAL) / FIG9_FOCAL
                eq = [p for m, w, h, p in out_cams.values()
                      if m == "EQUIRECTANGULAR"]
                if eq:
                    row["equirect_params_out"] = " ".join("%g" % x
                                                          for x in eq[0])
            intr.append(row)

    keys = ["subset", "mode", "status", "images", "points_in",
            "mean_rotation_error_deg", "max_rotation_error_deg",
            "rot_deg_EQUIRECTANGULAR", "rot_deg_PINHOLE",
            "mean_position_error", "pos_EQUIRECTANGULAR", "pos_PINHOLE",
            "reproj_px_EQUIRECTANGULAR",
            "reproj_px_PINHOLE", "mean_point_error", "num_points3D", "time_s"]
    print_table("Fig. 9 (hybrid set, %d rendered points): subsets, full BA "
                "(angular) and camera-only BA (tau 2 px)" % len(gt[2]),
                rows, keys)
    print_table("Fig. 9: PINHOLE focal +5%% in the input (true f = %g)"
                % FIG9_FOCAL, intr,
                ["subset", "refine_intrinsics", "status", "f_true", "f_input",
                 "fx_out", "fy_out", "cx_out", "cy_out", "f_rel_error",
                 "mean_rotation_error_deg", "mean_position_error",
                 "reproj_px_EQUIRECTANGULAR", "reproj_px_PINHOLE",
                 "mean_point_error"])
    for r in intr:
        r["mode"] = "full_f105_refine%d" % r["refine_intrinsics"]
    write_csv(os.path.join(root, "fig9.csv"), rows + intr)
    return rows, intr


def run_residual_types(args, bench, root, protocol, quick):
    """Angular vs pixel residual (full BA, same input) per camera type."""
    n_points = 600 if quick else 1000
    rng = random.Random("residual_types-%d" % args.seed)
    types = [
        ("EQUIRECTANGULAR", "room9_eq1024_%d" % n_points,
         ["--layout", "room9", "--model", "EQUIRECTANGULAR", "--width",
          "1024", "--height", "512"]),
        ("UNIFIED_OMNI", "room9_omni768_%d" % n_points,
         ["--layout", "room9", "--model", "UNIFIED_OMNI", "--width", "768",
          "--height", "768"]),
        ("PINHOLE", "ring_pinhole640_%d" % n_points,
         ["--layout", "ring", "--model", "PINHOLE", "--width", "640",
          "--height", "480"]),
    ]
    rows = []
    for model, name, extra in types:
        scene = os.path.join(root, "scenes", name)
        render(args, scene, extra + ["--points", str(n_points)])
        gt = read_model(os.path.join(scene, "sparse_gt"))
        path = os.path.join(root, "inputs", "rt_" + name)
        inp = perturb(gt, rng, **protocol)
        write_model(path, *inp)
        params = " ".join("%g" % x for x in list(gt[0].values())[0][3])
        res = []
        for residual in ("angular", "pixel"):
            r = bench.adjust_and_evaluate("rt_%s_%s" % (name, residual),
                                          scene, path, "full", residual,
                                          detail=True)
            row = {"camera": model, "layout": extra[1],
                   "images": len(gt[1]), "points_in": len(gt[2]),
                   "params": params}
            row.update(r)
            res.append(row)
        rows.extend(res)
        if all(r["status"] == "ok" for r in res):
            rows.append(ratio_row(res[0], res[1],
                                  {"camera": model, "layout": extra[1]}))
    print_table("Angular vs pixel residual per camera type (full BA, "
                "Cauchy 1 px)", rows,
                ["camera", "layout", "residual", "status", "points_in",
                 "mean_rotation_error_deg", "max_rotation_error_deg",
                 "mean_position_error", "mean_angular_error_px",
                 "mean_point_error", "time_s"])
    write_csv(os.path.join(root, "residual_types.csv"), rows)
    return rows


SIFT_SETS = ["room9_equirect", "room_poles", "room_fisheye190", "room_hybrid",
             "room_pinhole_ring"]


def run_sift_residuals(args, bench, root):
    """Angular vs pixel residual on real SIFT keypoints. Each rendered set of
    benchmark_sfm.py is reconstructed by the colmap pipeline
    (feature_extractor, exhaustive_matcher, mapper with the rendered
    intrinsics held), then the mapper's model is refined by a full BA with
    each residual: same observations and tracks, same solver settings
    (Cauchy 1 px), both scored against the ground truth. Unlike the
    synthetic protocol, whose noise is isotropic in pixels (so the pixel
    residual is its maximum-likelihood estimator), the noise here is the
    detector's own."""
    sfm_args = benchmark_sfm.make_parser().parse_args(
        ["--quick", "--no_upstream", "--output_dir", os.path.join(root, "sfm"),
         "--colmap", args.colmap, "--render", args.render])
    sfm = benchmark_sfm.Benchmark(sfm_args)
    rows = []
    for name in SIFT_SETS:
        sfm_row = {}
        try:
            scene = sfm.ensure_scene(name)
            run_dir = sfm.new_run_dir(name, "sphera")
            image_path, groups, gt, depth = sfm.rendered_inputs(scene, run_dir)
            print("%s: reconstructing" % name, flush=True)
            model = sfm.reconstruct(
                args.colmap, run_dir, image_path, groups, sfm_row,
                ["--Mapper.ba_refine_focal_length", "0",
                 "--Mapper.ba_refine_extra_params", "0"])
        except benchmark_sfm.StepError as error:
            rows.append({"dataset": name, "status": "sfm failed: %s" % error})
            continue
        res = []
        for residual in ("angular", "pixel"):
            r = bench.adjust_and_evaluate(
                "sift_%s_%s" % (name, residual), scene, model, "full",
                residual, gt_path=gt, depth_path=depth, detail=True)
            row = {"dataset": name, "registered": sfm_row.get("registered"),
                   "observations_px": "SIFT"}
            row.update(r)
            res.append(row)
        rows.extend(res)
        if all(r["status"] == "ok" for r in res):
            rows.append(ratio_row(res[0], res[1], {"dataset": name}))
    print_table("Angular vs pixel residual on SIFT keypoints (mapper's "
                "model, full BA, Cauchy 1 px)", rows,
                ["dataset", "residual", "status", "registered",
                 "num_points3D", "mean_rotation_error_deg",
                 "max_rotation_error_deg", "mean_position_error",
                 "mean_angular_error_px", "mean_point_error", "time_s"])
    write_csv(os.path.join(root, "sift_residuals.csv"), rows)
    return rows


def value_of(rows, match, k, scale=1.0):
    """rows' value of column k (times scale) in the first ok row that has
    every item of `match`; NaN when there is none."""
    for r in rows:
        if r.get("status") == "ok" and isinstance(r.get(k), (int, float)) \
                and all(r.get(mk) == mv for mk, mv in match.items()):
            return r[k] * scale
    return float("nan")


POSE_AND_POINT_PANELS = [
    ("mean_rotation_error_deg", 1.0, "mean rotation error [deg]"),
    ("mean_position_error", 1000.0, "mean position error [mm]"),
    ("mean_point_error", 1000.0, "mean 3D point error [mm]")]


def plot_fig9(root, rows, intr):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    subsets = ["hybrid", "spherical", "perspective"]
    modes = [("full", "full BA"), ("camera_only", "camera-only BA")]
    fig, axes = plt.subplots(1, 4, figsize=(15, 3.8))
    x = list(range(len(subsets)))
    for ax, (k, scale, label) in zip(axes, POSE_AND_POINT_PANELS):
        for j, (mode, ml) in enumerate(modes):
            ax.bar([i + (j - 0.5) * 0.38 for i in x],
                   [value_of(rows, {"subset": s, "mode": mode}, k, scale)
                    for s in subsets], 0.38, label=ml)
        ax.set_xticks(x)
        ax.set_xticklabels(subsets)
        ax.set_ylabel(label)
    axes[0].legend(fontsize=8)
    ax = axes[3]
    bars = [(m, t) for m, _ in modes for t in ("EQUIRECTANGULAR", "PINHOLE")]
    for j, (mode, t) in enumerate(bars):
        ax.bar([i + (j - 1.5) * 0.2 for i in x],
               [value_of(rows, {"subset": s, "mode": mode}, "reproj_px_" + t)
                for s in subsets], 0.2,
               label="%s, %s" % (mode, t.lower()))
    ax.set_xticks(x)
    ax.set_xticklabels(subsets)
    ax.set_ylabel("mean reprojection error [px eq.]")
    ax.legend(fontsize=7, loc="upper right", framealpha=0.9)
    ax.set_ylim(top=ax.get_ylim()[1] * 1.6)
    title = "Hybrid vs spherical-only vs perspective-only (cf. paper Fig. 9)"
    ref = [r for r in intr if r.get("subset") == "hybrid" and
           r.get("refine_intrinsics") == 1 and "fx_out" in r]
    if ref:
        title += "; hybrid, f +5%% refined: fx %.2f fy %.2f (true %g)" % (
            ref[0]["fx_out"], ref[0]["fy_out"], FIG9_FOCAL)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(root, "fig9.png"), dpi=120)


def plot_residual_comparison(path, rows, group_key, title):
    """Angular vs pixel bars per group (camera type or data set), with the
    pixel/angular ratio written over each pair."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    groups = []
    for r in rows:
        if r.get(group_key) not in groups:
            groups.append(r.get(group_key))
    fig, axes = plt.subplots(1, 3, figsize=(4 * 3 + 0.4 * len(groups), 3.8))
    x = list(range(len(groups)))
    for ax, (k, scale, label) in zip(axes, POSE_AND_POINT_PANELS):
        for j, res in enumerate(("angular", "pixel")):
            ax.bar([i + (j - 0.5) * 0.38 for i in x],
                   [value_of(rows, {group_key: g, "residual": res}, k, scale)
                    for g in groups], 0.38, label=res + " residual")
        for i, g in enumerate(groups):
            a = value_of(rows, {group_key: g, "residual": "angular"}, k)
            p = value_of(rows, {group_key: g, "residual": "pixel"}, k)
            if a > 0:
                ax.annotate("x%.2f" % (p / a), (i + 0.19, p * scale),
                            ha="center", va="bottom", fontsize=7)
        ax.set_xticks(x)
        ax.set_xticklabels([str(g).lower() for g in groups], fontsize=8,
                           rotation=20 if len(groups) > 3 else 0)
        ax.set_ylabel(label)
    axes[0].legend(fontsize=8)
    fig.suptitle(title + " (labels: pixel/angular)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


EXPERIMENTS = ("table1", "timing", "poles", "fig9", "residual_types",
               "sift_residuals")


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--output", default=os.path.join(REPO_ROOT, "build",
                                                     "bench"))
    ap.add_argument("--colmap", default=os.path.join(REPO_ROOT, "build", "bin",
                                                     "colmap"))
    ap.add_argument("--render", default=os.path.join(REPO_ROOT, "build",
                                                     "synthetic",
                                                     "sphera_render"))
    ap.add_argument("--wait", type=float, default=3600)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--only", default=",".join(EXPERIMENTS),
                    help="comma separated experiments among: %s "
                    "(table1 includes the Fig. 5 tau sweep; default: all)"
                    % ", ".join(EXPERIMENTS))
    args = ap.parse_args()
    only = [x.strip() for x in args.only.split(",") if x.strip()]
    unknown = [x for x in only if x not in EXPERIMENTS]
    if unknown or not only:
        ap.error("--only: unknown experiment(s) %s; choose from %s" %
                 (", ".join(unknown) or "(none)", ", ".join(EXPERIMENTS)))

    if not wait_for_command(args.colmap, args.wait):
        sys.exit("%s has no sphere_bundle_adjuster command" % args.colmap)
    root = os.path.join(args.output, "ba")
    os.makedirs(root, exist_ok=True)
    bench = Bench(args, root)
    rng = random.Random(args.seed)
    counts = [300, 600, 1200] if args.quick else [500, 1000, 2000]
    protocol = dict(sigma_px=0.5, outlier_rate=0.05, rot_deg=0.3, pos_m=0.02,
                    point_m=0.02)
    keys = ["run", "status", "mean_rotation_error_deg", "mean_position_error",
            "mean_angular_error_px", "mean_point_error", "num_points3D",
            "time_s"]
    sweep, timing = [], []

    if any(x in only for x in ("table1", "timing", "poles")):
        # Main scene: the paper's room, 9 panoramas, many points
        # (subsampled). The inputs are drawn whenever one of these three
        # experiments runs, so that each sees the same random stream.
        scene = os.path.join(root, "scenes", "room9_%d" % counts[-1])
        render(args, scene, ["--layout", "room9", "--model",
                             "EQUIRECTANGULAR", "--width", "2048", "--height",
                             "1024", "--points", str(counts[-1])])
        gt = read_model(os.path.join(scene, "sparse_gt"))
        ids = sorted(gt[2])
        inputs = {}
        for n in counts:
            keep = set(rng.sample(ids, min(n, len(ids))))
            path = os.path.join(root, "inputs", "room9_%d" % n)
            write_model(path, *perturb(gt, rng, keep_points=keep, **protocol))
            inputs[n] = path
        n_main = counts[1]

    if "table1" in only:
        # Table 1 and Fig. 5 (tau sweep) on the middle point count.
        table1 = []
        for residual in ("angular", "pixel"):
            table1.append(bench.adjust_and_evaluate(
                "full_%s_%d" % (residual, n_main), scene, inputs[n_main],
                "full", residual))
        for tau in (1, 2, 3, 4, 5):
            r = bench.adjust_and_evaluate("camonly_tau%d_%d" % (tau, n_main),
                                          scene, inputs[n_main], "camera_only",
                                          "angular", tau)
            sweep.append(r)
            if tau == 2:
                table1.append(r)
        print_table("Table 1 (room9, %d points): orientation / position error"
                    % n_main, table1, keys)
        print_table("Fig. 5: tau sweep (camera-only BA)", sweep,
                    ["tau_px"] + keys[1:])
        write_csv(os.path.join(root, "table1.csv"), table1)
        write_csv(os.path.join(root, "tau_sweep.csv"), sweep)

    if "timing" in only:
        # Camera-only vs full BA: time and accuracy for >= 3 point counts.
        for n in counts:
            for mode in ("full", "camera_only"):
                r = bench.adjust_and_evaluate(
                    "time_%s_%d" % (mode, n), scene, inputs[n], mode,
                    "angular", 2 if mode == "camera_only" else None)
                r["points_in"] = n
                timing.append(r)
        print_table("Camera-only (tau 2 px) vs full BA (angular)", timing,
                    ["points_in", "mode"] + keys[1:])
        write_csv(os.path.join(root, "timing.csv"), timing)

    if "poles" in only:
        # Pole-heavy scene: angular vs pixel residual.
        # The pole-heavy rig of benchmark_sfm.py (room_poles): 9 upright
        # panoramas alternately near the ceiling and near the floor.
        rig = os.path.join(root, "pole_rig.txt")
        write_rig(rig, poles_rig())
        pole_scene = os.path.join(root, "scenes", "poles_%d" % counts[-1])
        render(args, pole_scene, ["--rig", rig, "--points", str(counts[-1])])
        pgt = read_model(os.path.join(pole_scene, "sparse_gt"))
        # Keep the floor / ceiling points (|y| = 1.5): seen near the poles.
        keep = {pid for pid, p in pgt[2].items()
                if abs(abs(p["xyz"][1]) - 1.5) < 1e-6}
        ppath = os.path.join(root, "inputs", "poles")
        write_model(ppath, *perturb(pgt, rng, keep_points=keep, **protocol))
        poles = [bench.adjust_and_evaluate("poles_full_%s" % res, pole_scene,
                                           ppath, "full", res)
                 for res in ("angular", "pixel")]
        if all(r["status"] == "ok" for r in poles):
            poles.append(ratio_row(poles[0], poles[1],
                                   {"run": "pixel/angular ratio"}))
        print_table("Pole-heavy scene (%d floor/ceiling points)" % len(keep),
                    poles, keys)
        write_csv(os.path.join(root, "poles.csv"), poles)

    fig9_rows = fig9_intr = rt_rows = sift_rows = None
    if "fig9" in only:
        fig9_rows, fig9_intr = run_fig9(args, bench, root, protocol,
                                        args.quick)
    if "residual_types" in only:
        rt_rows = run_residual_types(args, bench, root, protocol, args.quick)
    if "sift_residuals" in only:
        sift_rows = run_sift_residuals(args, bench, root)

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        ok = [r for r in sweep if r["status"] == "ok"]
        if ok:
            fig, ax1 = plt.subplots(figsize=(6, 4))
            taus = [r["tau_px"] for r in ok]
            ax1.plot(taus, [r["mean_angular_error_px"] for r in ok], "o-",
                     color="tab:blue", label="mean reprojection error [px]")
            ax1.set_xlabel("tau [px]")
            ax1.set_ylabel("mean reprojection error [px]", color="tab:blue")
            ax2 = ax1.twinx()
            ax2.plot(taus, [r["mean_point_error"] for r in ok], "s--",
                     color="tab:red", label="mean 3D point error [m]")
            ax2.set_ylabel("mean 3D point error [m]", color="tab:red")
            ax1.set_title("Camera-only BA: tau sweep (cf. paper Fig. 5)")
            fig.tight_layout()
            fig.savefig(os.path.join(root, "fig5_tau_sweep.png"), dpi=120)
        okt = [r for r in timing if r["status"] == "ok"]
        if okt:
            fig, ax = plt.subplots(1, 2, figsize=(9, 3.5))
            for mode, mk in (("full", "o-"), ("camera_only", "s-")):
                rr = [r for r in okt if r["mode"] == mode]
                ax[0].plot([r["points_in"] for r in rr],
                           [r["time_s"] for r in rr], mk, label=mode)
                ax[1].plot([r["points_in"] for r in rr],
                           [r["mean_rotation_error_deg"] for r in rr], mk,
                           label=mode)
            ax[0].set_xlabel("points")
            ax[0].set_ylabel("time [s]")
            ax[1].set_xlabel("points")
            ax[1].set_ylabel("mean rotation error [deg]")
            ax[0].legend()
            fig.tight_layout()
            fig.savefig(os.path.join(root, "timing.png"), dpi=120)
        if fig9_rows is not None:
            plot_fig9(root, fig9_rows, fig9_intr)
        if rt_rows is not None:
            plot_residual_comparison(
                os.path.join(root, "residual_types.png"), rt_rows, "camera",
                "Angular vs pixel residual per camera type (full BA, "
                "synthetic noise isotropic in pixels)")
        if sift_rows is not None:
            plot_residual_comparison(
                os.path.join(root, "sift_residuals.png"), sift_rows,
                "dataset", "Angular vs pixel residual on SIFT keypoints "
                "(mapper's model, full BA)")
    except ImportError:
        print("python3-matplotlib missing: PNGs skipped")
    print("\nCSV and PNG written to", root)


if __name__ == "__main__":
    main()
