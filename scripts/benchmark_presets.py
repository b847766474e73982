#!/usr/bin/python3
"""Benchmark of the camera presets: a 360° camera's own files, rendered with
ground truth, through the one command a user runs (scripts/demo.sh --camera
NAME DIR), scored against the truth.

For every camera and seed:
  1. `colmap rig_preset --camera PRESET --resolution RES` gives the nominal
     rig: lens directions, nominal offsets, each lens's starting camera
     (its image circle's centre is the principal point).
  2. The true rig is the nominal one with every lens but the reference
     turned by a random rotation (--lens_turn_deg, about a random axis) and
     moved by a random offset (--lens_shift_mm): no real camera is nominal.
  3. sphera_render draws the true rig along a loop of frames through the
     room, every lens through a real-lens-like Kannala-Brandt polynomial
     (none of the models the mapper fits; benchmark_rig.py's shape) whose
     field's edge lands on the preset's image circle, with the sensor
     effects of a consumer camera (--realistic: circles cropped by the frame
     edge, housing, vignetting, flare, per-lens exposure and white balance,
     noise, JPEG), stored as the camera stores them: both lenses side by
     side in one file, or one file per lens (NAME_1.jpg ... NAME_8.jpg).
  4. scripts/demo.sh --camera PRESET DIR: split, extract with masks, the
     preset's rig config, match, rig_check, map, rig_calibration.
  5. The largest model against the truth: frames registered, every frame's
     rotation and position error after the similarity of the frame centres,
     and each lens's pose in the rig (rotation, centre in the rig scaled by
     that similarity), the start's (the nominal rig's) errors beside them.

Cameras (--cameras, comma separated):
  theta     ricoh_theta_v at 2k (1920x960, two 960x960 lenses side by side,
            202°, 2 cm), a Theta-like dual fisheye
  insta360  insta360_one_x2 at 4k (3840x1920, two 1920x1920 lenses, the back
            lens turned about the images' x axis), an Insta360-like one
  vuze      vuze (8 lenses of 1080x1920 in 4 stereo pairs 90° apart, 6 cm
            baselines, one file per lens NAME_k.jpg), an 8-lens camera

Usage (from the repository root, after scripts/build.sh):
  scripts/benchmark_presets.py                          5 seeds, theta
  scripts/benchmark_presets.py --cameras theta,insta360 --repeats 3
  scripts/benchmark_presets.py --camera_model OPENCV_FISHEYE
                                        the lenses start from that model
Output (--output, default build/bench_presets): preset_runs.csv (every run),
preset_results.csv (median and min..max per camera), preset_results.png,
logs and the demo's folders under runs/. Runs of an earlier call into the
same output that this call does not repeat (other cameras or seeds, e.g.
--first_seed 2 --repeats 3 after seeds 0-1) are kept in both CSVs and the
plot: use another --output for another program or option.
"""
import argparse
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sphera_common as common  # noqa: E402
from benchmark_rig import (KB_COEFFICIENTS, fmt, kb_radius,  # noqa: E402
                           spread_cell, write_csv)

REPO = common.REPO_ROOT

# name: (preset, resolution, how the camera stores its lenses, the preset's
# field of view in degrees, the size of one lens image at the resolution)
CAMERAS = {
    "theta": ("ricoh_theta_v", "2k", "side_by_side", 202.0, (960, 960)),
    "insta360": ("insta360_one_x2", "4k", "side_by_side", 200.0,
                 (1920, 1920)),
    "vuze": ("vuze", "", "files", 180.0, (1080, 1920)),
}


def log(message):
    print(f"[{time.strftime('%H:%M:%S')}] {message}", flush=True)


def start_radius(model, params, theta):
    """The image radius of a ray THETA off the axis through the starting
    camera MODEL PARAMS (fx first): where its image circle is."""
    fx = params[0]
    s, c = math.sin(theta), math.cos(theta)
    if model == "DOUBLE_SPHERE":
        xi, alpha = params[4], params[5]
        zz = xi + c
        d2 = math.hypot(s, zz)
        return fx * s / (alpha * d2 + (1 - alpha) * zz)
    if model == "EUCM":
        alpha, beta = params[4], params[5]
        return fx * s / (alpha * math.sqrt(beta * s * s + c * c) +
                         (1 - alpha) * c)
    raise ValueError(f"starting model {model}: DOUBLE_SPHERE or EUCM")


def random_turn(rng, angle_deg):
    """A rotation matrix of ANGLE_DEG about a random axis."""
    import numpy as np
    axis = np.array([rng.gauss(0, 1) for _ in range(3)])
    axis /= np.linalg.norm(axis)
    a = math.radians(angle_deg)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]],
                  [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(a) * k + (1 - math.cos(a)) * k @ k


def nominal_rig(nominal):
    """[(camera, R cam_from_rig, lens centre in the rig)] of the lenses of
    a rig_config.json list NOMINAL."""
    import numpy as np
    lenses = []
    for camera in nominal[0]["cameras"]:
        rotation = common.rotation_from_quaternion(
            *camera.get("cam_from_rig_rotation", [1, 0, 0, 0]))
        translation = np.array(camera.get("cam_from_rig_translation",
                                          [0, 0, 0]), dtype=float)
        lenses.append((camera, rotation, -rotation.T @ translation))
    return lenses


def true_rig(nominal_lenses, rng, turn_deg, shift_mm):
    """nominal_rig's lenses, each but the first turned and moved: the true
    rig."""
    import numpy as np
    lenses = []
    for k, (camera, rotation, centre) in enumerate(nominal_lenses):
        if k > 0:
            rotation = random_turn(rng, turn_deg) @ rotation
            direction = np.array([rng.gauss(0, 1) for _ in range(3)])
            centre = centre + direction / np.linalg.norm(direction) * \
                shift_mm / 1000
        lenses.append((camera, rotation, centre))
    return lenses


def sensors_file(lenses, lens_size, half_field_deg, path):
    """sphera_render's --rig_sensors lines of LENSES (true_rig): every lens
    a Kannala-Brandt lens centred on its starting camera's principal point,
    the field's edge on the starting camera's image circle."""
    theta = math.radians(half_field_deg)
    lines = []
    for k, (camera, rotation, centre) in enumerate(lenses):
        params = camera["camera_params"]
        radius = start_radius(camera["camera_model_name"], params, theta)
        # Just inside the circle, which the renderer wants in the image;
        # a circle cropped by the frame (the Vuze's) is not given as the
        # lens's field: the frame crops the lens's image instead.
        f = 0.999 * radius / kb_radius(1.0, theta)
        kb = [f, f, params[2], params[3], *KB_COEFFICIENTS]
        q = common.quaternion_from_matrix(rotation.tolist())
        t = -rotation @ centre
        inside = radius <= min(params[2], params[3],
                               lens_size[0] - params[2],
                               lens_size[1] - params[3])
        lines.append(" ".join(
            [f"lens{k}", "OPENCV_FISHEYE", str(lens_size[0]),
             str(lens_size[1]), *("%.17g" % v for v in kb), "|",
             *("%.17g" % v for v in (*q, *t)),
             *(["%.17g" % half_field_deg] if inside else [])]))
    with open(path, "w") as f_out:
        f_out.write("\n".join(lines) + "\n")


def camera_files(scene, lenses, storage, folder):
    """The camera's own files of the rendered SCENE in FOLDER: the renderer's
    raw side-by-side frames, or each lens image as NAME<suffix>."""
    if storage == "side_by_side":
        shutil.copytree(os.path.join(scene, "raw"), folder)
        return
    os.makedirs(folder)
    for k, (camera, _, _) in enumerate(lenses):
        suffix = camera["image_suffix"]
        for name in sorted(os.listdir(os.path.join(scene, "images",
                                                   f"lens{k}"))):
            stem = os.path.splitext(name)[0]
            shutil.copy(os.path.join(scene, "images", f"lens{k}", name),
                        os.path.join(folder, stem + suffix))


def truth_name(name, lenses, storage):
    """The ground truth's image name (lensK/NAME.jpg) of a model's image."""
    if storage == "side_by_side":
        return name
    for k, (camera, _, _) in enumerate(lenses):
        suffix = camera["image_suffix"]
        if name.endswith(suffix):
            return f"lens{k}/{name[:-len(suffix)]}.jpg"
    return None


def score(gt_path, model_path, lenses, storage, nominal_lenses):
    """Frame and lens errors of the text model at MODEL_PATH against the
    truth at GT_PATH."""
    import numpy as np
    num = len(lenses)
    gt = common.text_model_poses(gt_path)
    est = {}
    for name, pose in common.text_model_poses(model_path).items():
        truth = truth_name(name, lenses, storage)
        if truth:
            est[truth] = pose
    row = {"images": len(gt), "registered_images": len(est)}
    gt_frames = common.rig_frame_poses(gt, num)
    est_frames = common.rig_frame_poses(est, num)
    row["frames"] = len(gt_frames)
    row["registered"] = len(est_frames)
    errors = common.aligned_pose_errors(gt_frames, est_frames)
    if errors:
        row["rot_median_deg"] = common.median([e[0] for e in errors.values()])
        row["pos_median_mm"] = 1000 * common.median(
            [e[1] for e in errors.values()])
    # Each lens's pose in the rig: cam_from_rig = cam_from_world of the lens
    # composed with world_from_rig of lens 0 (the rig frame), per frame,
    # the median over the frames holding both.
    names = sorted(set(gt) & set(est))
    if len(names) < 3:
        return row
    scale, _, _ = common.similarity_of_centres(
        np.array([est[n][1] for n in names]),
        np.array([gt[n][1] for n in names]))
    rot_errors, centre_errors, start_rot, start_centre = [], [], [], []
    for k in range(1, num):
        per_frame_rot, per_frame_centre = [], []
        for frame in sorted(set(f.split("/")[-1] for f in names)):
            ref, lens = f"lens0/{frame}", f"lens{k}/{frame}"
            if ref not in est or lens not in est:
                continue
            r0, c0 = est[ref]
            rk, ck = est[lens]
            rotation = rk @ r0.T  # lens k from lens 0 (the rig)
            centre = r0 @ (ck - c0) * scale  # lens k's centre in the rig
            true_rotation, true_centre = lenses[k][1], lenses[k][2]
            relative = true_rotation @ rotation.T
            per_frame_rot.append(math.degrees(math.acos(
                max(-1.0, min(1.0, (np.trace(relative) - 1) / 2)))))
            per_frame_centre.append(
                1000 * float(np.linalg.norm(centre - true_centre)))
        if per_frame_rot:
            rot_errors.append(common.median(per_frame_rot))
            centre_errors.append(common.median(per_frame_centre))
        _, nominal_rotation, nominal_centre = nominal_lenses[k]
        relative = lenses[k][1] @ nominal_rotation.T
        start_rot.append(math.degrees(math.acos(
            max(-1.0, min(1.0, (np.trace(relative) - 1) / 2)))))
        start_centre.append(1000 * float(np.linalg.norm(
            nominal_centre - lenses[k][2])))
    if rot_errors:
        row["lens_rot_max_deg"] = max(rot_errors)
        row["lens_centre_max_mm"] = max(centre_errors)
    row["start_rot_max_deg"] = max(start_rot)
    row["start_centre_max_mm"] = max(start_centre)
    return row


def run_one(args, name, seed, work):
    preset, resolution, storage, field_of_view, lens_size = CAMERAS[name]
    os.makedirs(work)
    logs = os.path.join(work, "logs")
    os.makedirs(logs)
    nominal_path = os.path.join(work, "nominal_rig_config.json")
    command = [args.colmap, "rig_preset", "--camera", preset,
               "--output_path", nominal_path]
    if resolution:
        command += ["--resolution", resolution]
    code, _ = common.run_logged(command, os.path.join(logs, "preset.log"),
                                600)
    if code:
        raise RuntimeError(f"rig_preset failed: {logs}/preset.log")
    with open(nominal_path) as f:
        nominal = json.load(f)
    half_field = args.half_field_deg or field_of_view / 2
    nominal_lenses = nominal_rig(nominal)
    lenses = true_rig(nominal_lenses, random.Random(seed),
                      args.lens_turn_deg, args.lens_shift_mm)
    sensors = os.path.join(work, "sensors.txt")
    sensors_file(lenses, lens_size, half_field, sensors)
    scene = os.path.join(work, "scene")
    render = ["--rig_sensors", sensors, "--frames", args.frames, "--seed",
              seed, "--supersample", args.supersample, "--realistic"]
    render += common.render_options(args)
    if storage == "side_by_side":
        render.append("--raw")
    started = time.monotonic()
    common.run_render(scene, *render, program=args.render)
    t_render = time.monotonic() - started
    files = os.path.join(work, "camera_files")
    camera_files(scene, lenses, storage, files)
    demo_dir = os.path.join(work, "demo")
    env = dict(os.environ, SPHERA_DEMO_DIR=demo_dir,
               SPHERA_COLMAP=args.colmap, SPHERA_RENDER=args.render,
               SPHERA_DEMO_SEED=str(seed),
               SPHERA_DEMO_FLAT_FIELD="1" if args.flat_field else "0")
    demo = [os.path.join(REPO, "scripts", "demo.sh"), "--camera", preset,
            files]
    if args.camera_model:
        demo.append(args.camera_model)
    code, t_demo = common.run_logged(
        demo,
        os.path.join(logs, "demo.log"), 7200, env=env)
    row = {"camera": name, "preset": preset, "seed": seed,
           "model": args.camera_model or nominal[0]["cameras"][0][
               "camera_model_name"],
           "t_render_s": t_render, "t_demo_s": t_demo}
    with open(os.path.join(logs, "demo.log")) as f:
        output = f.read()
    mapped = re.search(r"mapping: +(\d+) of (\d+) images registered in "
                       r"(?:(1) model|the largest of (\d+) models)", output)
    if mapped:
        row["models"] = int(mapped.group(3) or mapped.group(4))
    # The model the demo calibrated the rig on: its largest.
    calibrated = re.search(r"lens poses and intrinsics of model (\S+) in",
                           output)
    if code or not calibrated:
        row["error"] = f"demo exit {code}" if code else "no model"
        return row
    model = os.path.join(demo_dir, "sparse", calibrated.group(1))
    text = os.path.join(work, "model_text")
    common.model_to_text(model, text)
    row.update(score(os.path.join(scene, "sparse_gt"), text, lenses,
                     storage, nominal_lenses))
    return row


COLUMNS = ["camera", "preset", "seed", "frames", "registered", "models",
           "rot_median_deg", "pos_median_mm", "lens_rot_max_deg",
           "lens_centre_max_mm", "start_rot_max_deg", "start_centre_max_mm",
           "t_render_s", "t_demo_s", "error"]
SPREAD = ["rot_median_deg", "pos_median_mm", "lens_rot_max_deg",
          "lens_centre_max_mm", "t_demo_s"]


def summarize(runs):
    summary = []
    for name in dict.fromkeys(r["camera"] for r in runs):
        rows = [r for r in runs if r["camera"] == name]
        out = {"camera": name, "runs": len(rows),
               "failed": sum(1 for r in rows if r.get("error")),
               "all_registered": sum(
                   1 for r in rows if r.get("registered") and
                   r.get("registered") == r.get("frames") and
                   r.get("models") == 1)}
        out.update(common.medians_and_spreads(rows, COLUMNS[3:-1], SPREAD))
        summary.append(out)
    return summary


def print_table(summary):
    header = ["camera", "every frame, one model", "frame rot deg",
              "frame pos mm", "lens rot deg", "lens centre mm",
              "start: lens rot deg / centre mm", "demo s"]
    lines = [header]
    for row in summary:
        def cell(key):
            return spread_cell(row, key)
        lines.append([row["camera"], f"{row['all_registered']}/{row['runs']}",
                      cell("rot_median_deg"), cell("pos_median_mm"),
                      cell("lens_rot_max_deg"), cell("lens_centre_max_mm"),
                      f"{fmt(row.get('start_rot_max_deg'))} / "
                      f"{fmt(row.get('start_centre_max_mm'))}",
                      cell("t_demo_s")])
    widths = [max(len(str(line[i])) for line in lines)
              for i in range(len(header))]
    for line in lines:
        print("  ".join(str(v).ljust(w) for v, w in zip(line, widths)))


def write_png(path, runs):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = list(dict.fromkeys(r["camera"] for r in runs))
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, key, start_key, title in (
            (axes[0], "lens_rot_max_deg", "start_rot_max_deg",
             "lens rotation in the rig, deg (worst lens)"),
            (axes[1], "lens_centre_max_mm", "start_centre_max_mm",
             "lens centre in the rig, mm (worst lens)")):
        for i, name in enumerate(names):
            values = [float(r[key]) for r in runs if r["camera"] == name
                      and r.get(key) not in (None, "")]
            starts = [float(r[start_key]) for r in runs
                      if r["camera"] == name and
                      r.get(start_key) not in (None, "")]
            ax.scatter([i - 0.1] * len(values), values, color="tab:green",
                       label="calibrated" if i == 0 else None)
            ax.scatter([i + 0.1] * len(starts), starts, color="tab:grey",
                       marker="x", label="nominal start" if i == 0 else None)
        ax.axhline(0.02 if key == "lens_rot_max_deg" else 1.0, color="tab:red",
                   linestyle="--", linewidth=1, label="target")
        ax.set_xticks(range(len(names)))
        ax.set_xticklabels(names)
        ax.set_yscale("log")
        ax.set_title(title, fontsize=10)
        ax.legend(fontsize=8)
    fig.suptitle("Camera presets on realistic renders, scripts/demo.sh "
                 "--camera: every seed")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    parser.add_argument("--colmap", default=os.path.join(REPO, "build", "bin",
                                                         "colmap"))
    parser.add_argument("--render", default=os.path.join(
        REPO, "build", "synthetic", "sphera_render"))
    parser.add_argument("--cameras", default="theta")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--first_seed", type=int, default=0)
    parser.add_argument("--frames", type=int, default=6)
    parser.add_argument("--supersample", type=int, default=1)
    parser.add_argument("--lens_turn_deg", type=float, default=0.5,
                        help="each lens's true rotation off the nominal rig")
    parser.add_argument("--lens_shift_mm", type=float, default=2.0,
                        help="each lens's true centre off the nominal rig")
    parser.add_argument("--camera_model", default="",
                        help="the lenses' starting model (demo.sh --camera "
                        "NAME DIR MODEL; default: the preset's)")
    parser.add_argument("--half_field_deg", type=float, default=0,
                        help="the lenses' half field (0: the preset's)")
    common.add_render_option_argument(parser)
    parser.add_argument("--flat_field", action="store_true",
                        help="the splitter divides out each lens's light "
                        "fall-off (SPHERA_DEMO_FLAT_FIELD=1)")
    parser.add_argument("--output", default=os.path.join(REPO, "build",
                                                         "bench_presets"))
    args = parser.parse_args()
    for program in (args.colmap, args.render):
        if not os.path.isfile(program):
            sys.exit(f"error: {program} is not built (scripts/build.sh)")
    common.COLMAP = args.colmap
    names = args.cameras.split(",")
    for name in names:
        if name not in CAMERAS:
            sys.exit(f"error: --cameras {name}: one of {', '.join(CAMERAS)}")
    os.makedirs(args.output, exist_ok=True)
    seeds = range(args.first_seed, args.first_seed + args.repeats)
    runs_csv = os.path.join(args.output, "preset_runs.csv")
    runs = common.earlier_runs(
        runs_csv, lambda row: row.get("camera") in names
        and row.get("seed") in seeds)
    if runs:
        log(f"kept {len(runs)} run(s) of an earlier call in {runs_csv}")
    for name in names:
        for seed in seeds:
            work = os.path.join(args.output, "runs", f"{name}_seed{seed}")
            shutil.rmtree(work, ignore_errors=True)
            log(f"{name} seed {seed}")
            try:
                row = run_one(args, name, seed, work)
            except (RuntimeError, subprocess.CalledProcessError) as error:
                row = {"camera": name, "seed": seed, "error": str(error)}
            log("  " + ", ".join(f"{k} {fmt(v)}" for k, v in row.items()
                                 if k not in ("camera", "preset", "seed")))
            runs.append(row)
            write_csv(runs_csv, runs)
    summary = summarize(runs)
    print_table(summary)
    write_csv(os.path.join(args.output, "preset_results.csv"), summary)
    write_png(os.path.join(args.output, "preset_results.png"), runs)
    print(f"wrote {args.output}/preset_runs.csv, preset_results.csv, "
          "preset_results.png")


if __name__ == "__main__":
    main()
