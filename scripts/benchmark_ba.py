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

Outputs under OUTPUT/ba/: table1.csv, tau_sweep.csv, timing.csv, poles.csv,
fig5_tau_sweep.png, timing.png; tables are printed. Scenes are rendered once
into OUTPUT/ba/scenes/ (sphera_render --supersample 1) and reused.

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

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


# ---------------------------------------------------------------------------
# COLMAP text model I/O
# ---------------------------------------------------------------------------
def read_model(path):
    cameras, images, points = {}, {}, {}
    with open(os.path.join(path, "cameras.txt")) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            e = line.split()
            cameras[int(e[0])] = (e[1], int(e[2]), int(e[3]),
                                  [float(x) for x in e[4:]])
    with open(os.path.join(path, "images.txt")) as f:
        lines = [l for l in f if not l.startswith("#")]
    for i in range(0, len(lines) - 1, 2):
        e = lines[i].split()
        if not e:
            continue
        obs = lines[i + 1].split()
        pts = [[float(obs[k]), float(obs[k + 1]), int(obs[k + 2])]
               for k in range(0, len(obs), 3)]
        images[int(e[0])] = {
            "q": [float(x) for x in e[1:5]], "t": [float(x) for x in e[5:8]],
            "camera_id": int(e[8]), "name": e[9], "points2D": pts}
    with open(os.path.join(path, "points3D.txt")) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            e = line.split()
            track = [(int(e[k]), int(e[k + 1])) for k in range(8, len(e), 2)]
            points[int(e[0])] = {"xyz": [float(x) for x in e[1:4]],
                                 "rgb": e[4:7], "track": track}
    return cameras, images, points


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
# Small quaternion helpers (w, x, y, z), no numpy needed here.
# ---------------------------------------------------------------------------
def qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return [w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2]


def qrot(q, v):
    p = qmul(qmul(q, [0.0] + list(v)), [q[0], -q[1], -q[2], -q[3]])
    return p[1:]


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
        c = [-x for x in qrot(qi, im["t"])]
        axis = random_unit(rng)
        ang = math.radians(rot_deg)
        dq = [math.cos(ang / 2)] + [math.sin(ang / 2) * a for a in axis]
        q2 = qmul(dq, q)
        c2 = [c[k] + pos_m * d for k, d in enumerate(random_unit(rng))]
        im["q"] = q2
        im["t"] = [-x for x in qrot(q2, c2)]
    for pid, p in points.items():
        d = random_unit(rng)
        p["xyz"] = [p["xyz"][k] + point_m * d[k] for k in range(3)]
    return cameras, images, points


# ---------------------------------------------------------------------------
def run(cmd, log, timeout=3600):
    t0 = time.time()
    with open(log, "w") as f:
        f.write("$ " + " ".join(cmd) + "\n")
        f.flush()
        rc = subprocess.call(cmd, stdout=f, stderr=subprocess.STDOUT,
                             timeout=timeout)
    return rc, time.time() - t0


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
    cmd = [args.render, "--output", out_dir, "--supersample", "1",
           "--seed", str(args.seed)] + extra
    print("rendering", out_dir, flush=True)
    subprocess.check_call(cmd, stdout=subprocess.DEVNULL)


class Bench:
    def __init__(self, args, root):
        self.args = args
        self.root = root

    def adjust_and_evaluate(self, tag, scene, input_model, mode, residual,
                            tau=None):
        a = self.args
        work = os.path.join(self.root, "runs", tag)
        if os.path.exists(work):
            shutil.rmtree(work)
        os.makedirs(work)
        out = os.path.join(work, "model")
        total = 0.0
        base = [a.colmap, "sphere_bundle_adjuster", "--output_path", out]
        if mode == "full":
            rc, dt = run(base + ["--input_path", input_model, "--mode", "full",
                                 "--residual", residual, "--loss", "cauchy",
                                 "--loss_scale_px", "1"],
                         os.path.join(work, "ba.log"))
            total += dt
        else:
            stage1 = os.path.join(work, "stage1")
            rc, dt = run([a.colmap, "sphere_bundle_adjuster", "--input_path",
                          input_model, "--output_path", stage1, "--mode",
                          "camera_only", "--tau_px", "8", "--max_iterations",
                          "5"], os.path.join(work, "stage1.log"))
            total += dt
            if rc == 0:
                rc, dt = run(base + ["--input_path", stage1, "--mode",
                                     "camera_only", "--tau_px", str(tau),
                                     "--max_iterations", "20"],
                             os.path.join(work, "ba.log"))
                total += dt
        row = {"run": tag, "mode": mode, "residual": residual,
               "tau_px": "" if tau is None else tau, "status": "ok",
               "time_s": round(total, 3)}
        if rc != 0:
            row["status"] = "ba_failed"
            return row
        ev = os.path.join(work, "eval")
        os.makedirs(ev)
        rc, _ = run([a.colmap, "model_evaluator", "--gt_path",
                     os.path.join(scene, "sparse_gt"), "--input_path", out,
                     "--depth_path", os.path.join(scene, "depth"),
                     "--output_path", ev], os.path.join(work, "eval.log"))
        if rc != 0:
            row["status"] = "eval_failed"
            return row
        with open(os.path.join(ev, "evaluation.json")) as f:
            e = json.load(f)
        for k in ["mean_rotation_error_deg", "mean_position_error",
                  "mean_angular_error_px", "mean_point_error",
                  "median_point_error", "num_points3D"]:
            row[k] = e.get(k, "")
        return row


def write_csv(path, rows):
    keys = []
    for r in rows:
        for k in r:
            if k not in keys:
                keys.append(k)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
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


def pole_rig(path):
    """9 upright equirectangular cameras (poles at floor and ceiling),
    alternately near the ceiling and near the floor, so floor/ceiling features
    are seen close to the poles."""
    with open(path, "w") as f:
        f.write("# NAME MODEL W H PARAMS | QW QX QY QZ TX TY TZ\n")
        k = 0
        for gz in (-1, 0, 1):
            for gx in (-1, 0, 1):
                y = -0.9 if (k % 2 == 0) else 0.9  # +Y is down
                c = (gx * 0.8, y, gz * 0.8)
                f.write("pole%03d.jpg EQUIRECTANGULAR 2048 1024 2048 1024 | "
                        "1 0 0 0 %r %r %r\n" % (k, -c[0], -c[1], -c[2]))
                k += 1


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
    args = ap.parse_args()

    if not wait_for_command(args.colmap, args.wait):
        sys.exit("%s has no sphere_bundle_adjuster command" % args.colmap)
    root = os.path.join(args.output, "ba")
    os.makedirs(root, exist_ok=True)
    bench = Bench(args, root)
    rng = random.Random(args.seed)
    counts = [300, 600, 1200] if args.quick else [500, 1000, 2000]

    # Main scene: the paper's room, 9 panoramas, many points (subsampled).
    scene = os.path.join(root, "scenes", "room9_%d" % counts[-1])
    render(args, scene, ["--layout", "room9", "--model", "EQUIRECTANGULAR",
                         "--width", "2048", "--height", "1024", "--points",
                         str(counts[-1])])
    gt = read_model(os.path.join(scene, "sparse_gt"))
    ids = sorted(gt[2])
    protocol = dict(sigma_px=0.5, outlier_rate=0.05, rot_deg=0.3, pos_m=0.02,
                    point_m=0.02)

    inputs = {}
    for n in counts:
        keep = set(rng.sample(ids, min(n, len(ids))))
        path = os.path.join(root, "inputs", "room9_%d" % n)
        write_model(path, *perturb(gt, rng, keep_points=keep, **protocol))
        inputs[n] = path
    n_main = counts[1]

    # Table 1 and Fig. 5 (tau sweep) on the middle point count.
    table1, sweep = [], []
    for residual in ("angular", "pixel"):
        table1.append(bench.adjust_and_evaluate(
            "full_%s_%d" % (residual, n_main), scene, inputs[n_main], "full",
            residual))
    for tau in (1, 2, 3, 4, 5):
        r = bench.adjust_and_evaluate("camonly_tau%d_%d" % (tau, n_main),
                                      scene, inputs[n_main], "camera_only",
                                      "angular", tau)
        sweep.append(r)
        if tau == 2:
            table1.append(r)
    keys = ["run", "status", "mean_rotation_error_deg", "mean_position_error",
            "mean_angular_error_px", "mean_point_error", "num_points3D",
            "time_s"]
    print_table("Table 1 (room9, %d points): orientation / position error" %
                n_main, table1, keys)
    print_table("Fig. 5: tau sweep (camera-only BA)", sweep,
                ["tau_px"] + keys[1:])
    write_csv(os.path.join(root, "table1.csv"), table1)
    write_csv(os.path.join(root, "tau_sweep.csv"), sweep)

    # Camera-only vs full BA: time and accuracy for >= 3 point counts.
    timing = []
    for n in counts:
        for mode in ("full", "camera_only"):
            r = bench.adjust_and_evaluate(
                "time_%s_%d" % (mode, n), scene, inputs[n], mode, "angular",
                2 if mode == "camera_only" else None)
            r["points_in"] = n
            timing.append(r)
    print_table("Camera-only (tau 2 px) vs full BA (angular)", timing,
                ["points_in", "mode"] + keys[1:])
    write_csv(os.path.join(root, "timing.csv"), timing)

    # Pole-heavy scene: angular vs pixel residual.
    rig = os.path.join(root, "pole_rig.txt")
    pole_rig(rig)
    pole_scene = os.path.join(root, "scenes", "poles_%d" % counts[-1])
    render(args, pole_scene, ["--rig", rig, "--points", str(counts[-1])])
    pgt = read_model(os.path.join(pole_scene, "sparse_gt"))
    # Keep the floor / ceiling points (|y| = 1.5): seen near the poles.
    keep = {pid for pid, p in pgt[2].items() if abs(abs(p["xyz"][1]) - 1.5)
            < 1e-6}
    ppath = os.path.join(root, "inputs", "poles")
    write_model(ppath, *perturb(pgt, rng, keep_points=keep, **protocol))
    poles = [bench.adjust_and_evaluate("poles_full_%s" % res, pole_scene,
                                       ppath, "full", res)
             for res in ("angular", "pixel")]
    if all(r["status"] == "ok" for r in poles):
        ratio = {"run": "pixel/angular ratio", "status": ""}
        for k in ("mean_rotation_error_deg", "mean_position_error",
                  "mean_point_error"):
            a, p = poles[0].get(k), poles[1].get(k)
            if isinstance(a, (int, float)) and a > 0 and \
                    isinstance(p, (int, float)):
                ratio[k] = p / a
        poles.append(ratio)
    print_table("Pole-heavy scene (%d floor/ceiling points)" % len(keep),
                poles, keys)
    write_csv(os.path.join(root, "poles.csv"), poles)

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
    except ImportError:
        print("python3-matplotlib missing: PNGs skipped")
    print("\nCSV and PNG written to", root)


if __name__ == "__main__":
    main()
