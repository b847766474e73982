#!/usr/bin/python3
"""Benchmark of multi-lens 360° cameras: the raw rig against the stitched
panorama and against one lens alone, on the same rendered frames.

For every seed and preset, sphera_render renders a rig along a loop of
frames (dual_fisheye: two back-to-back 200° lenses 3 cm apart, also the raw
side-by-side frames and the equirectangular panoramas a stitcher makes of
them; ring8: 8 outward 195° lenses on a 6 cm ring). Each system runs the
COLMAP command line (feature_extractor, rig_configurator where it applies,
exhaustive_matcher, mapper) and is scored per frame against the ground
truth:

  rig        SPHERA: every lens image, one camera per lens with the lens's
             image-circle mask, rig_configurator with a start that only
             knows the lenses' directions (no offsets), frames mapped as rigs
  stitched   SPHERA on the stitched panoramas (EQUIRECTANGULAR), one per
             frame (dual_fisheye only)
  stitched_upstream  unpatched upstream COLMAP 4.x on the same panoramas
             (--upstream_colmap; left out with --no_upstream)
  one_lens   SPHERA on lens 0's images alone (one 200° or 195° lens)

A frame's position is the mean of its lens centres for the rig (the
stitched panorama's centre, where the ground truth puts the panorama), lens
0's centre for one_lens; its rotation is lens 0's (the panorama is oriented
as lens 0). Each model is aligned to the ground truth by the least-squares
similarity of these positions (Umeyama); errors are the angle of
R_gt R_est^T and the distance of the aligned positions. For the rig, the
recovered sensor_from_rig of every lens is compared with the truth
(rotation angle, lens centre in the rig scaled by the alignment's scale).

Usage (from the repository root, after scripts/build.sh):
  scripts/benchmark_rig.py                        3 seeds, both presets
  scripts/benchmark_rig.py --repeats 1 --presets dual_fisheye --frames 10
  scripts/benchmark_rig.py --first_seed 1 --repeats 2 ...   adds seeds 1, 2
  scripts/benchmark_rig.py --reuse_database build/bench_rig --output DIR ...
                                                  maps the databases of an
                                                  earlier output again (the
                                                  same options), e.g. with
                                                  another --colmap; with
                                                  --fit_model, the rig is
                                                  configured again from that
                                                  model's rough start (the
                                                  earlier run's verified
                                                  matches kept)
  scripts/benchmark_rig.py --start_focal_scale 1.2 --start_no_distortion ...
                                                  self-calibration: the rig
                                                  starts from focal lengths
                                                  20% long, no distortion
Lenses that lie like real ones (the real-lenses issue):
  --lens kb       every lens of the preset drawn through a Kannala-Brandt
                  polynomial of a real-lens-like shape (OPENCV_FISHEYE over
                  its whole field, 200° or 195°), not one of the models the
                  mapper fits
  --realistic     sphera_render's sensor effects (cropped circles, housing,
                  vignetting, flare, per-lens exposure and white balance,
                  noise, JPEG)
  --fit_model M   the rig starts from model M (EUCM, DOUBLE_SPHERE,
                  UNIFIED_OMNI or OPENCV_FISHEYE, the drawn lenses' own
                  family) with rough intrinsics from each lens's image
                  circle and field of view (principal point at the image
                  centre, focal length so that the field's edge lands on the
                  circle) and zero offsets, and self-calibrates
  scripts/benchmark_rig.py --systems rig --lens kb --realistic \
      --fit_model DOUBLE_SPHERE --repeats 5 --output build/bench_rig_kb
Output (--output, default build/bench_rig): rig_runs.csv (every run),
rig_results.csv (median and min..max per preset and system, ratios to the
rig), rig_results.png, logs/.
"""
import argparse
import csv
import os
import shlex
import shutil
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sphera_common as common  # noqa: E402

REPO = common.REPO_ROOT


def log(message):
    print(f"[{time.strftime('%H:%M:%S')}] {message}", flush=True)


def timed(program, args, log_path, timeout=3600):
    """Runs PROGRAM ARGS logging into LOG_PATH; returns seconds. A failure
    raises RuntimeError with the log's end."""
    code, seconds = common.run_logged([program, *map(str, args)], log_path,
                                      timeout)
    if code != 0:
        with open(log_path, errors="replace") as f:
            tail = f.read()[-1500:]
        raise RuntimeError(f"{os.path.basename(log_path)}: exit {code}\n"
                           f"{tail}")
    return seconds


def frame_of(name):
    """The frame an image belongs to: 'lens0/frame003.jpg' and
    'frame003.jpg' are frame 'frame003.jpg'."""
    return name.split("/")[-1]


def frame_poses(model_path, system, num_lenses):
    """{frame: (R of lens 0 or the panorama, position)} of a text model."""
    poses = common.text_model_poses(model_path)
    if system == "rig":
        return common.rig_frame_poses(poses, num_lenses)
    return {frame_of(name): pose for name, pose in poses.items()}


def rough_rig_config(scene, path, focal_scale=1.0, no_distortion=False):
    """rig_config.json of the scene with every lens's offset set to zero:
    what a user knows of a camera (lens directions), not its calibration;
    the focal lengths scaled by FOCAL_SCALE and, with NO_DISTORTION, the
    lenses' distortion unknown (common.rough_intrinsics)."""
    import json
    with open(os.path.join(scene, "rig_config.json")) as f:
        config = common.rough_intrinsics(
            common.without_rig_offsets(json.load(f)), focal_scale,
            no_distortion)
    with open(path, "w") as f:
        json.dump(config, f, indent=1)


# Real-lens-like Kannala-Brandt shape r = f (t + k1 t^3 + k2 t^5 + k3 t^7 +
# k4 t^9): slightly compressed towards the rim, monotone to 110 degrees.
KB_COEFFICIENTS = (-0.012, 0.0016, -0.0002, 0.0)
# Half fields of view of the presets' lenses, degrees.
PRESET_HALF_FIELD_DEG = {"dual_fisheye": 100.0, "ring8": 97.5}


def kb_radius(f, theta, k=KB_COEFFICIENTS):
    return f * (theta + k[0] * theta ** 3 + k[1] * theta ** 5 +
                k[2] * theta ** 7 + k[3] * theta ** 9)


def kb_sensors_file(layout_config, lens_size, half_field_deg, path):
    """A --rig_sensors file of the preset's lenses (their poses from the
    preset's LAYOUT_CONFIG, a rig_config.json list) drawn through the
    Kannala-Brandt shape above, the field's edge at 0.48 of LENS_SIZE from
    the image centre."""
    import math
    theta = math.radians(half_field_deg)
    f = 0.48 * lens_size / kb_radius(1.0, theta)
    c = lens_size / 2.0
    lines = []
    for camera in layout_config[0]["cameras"]:
        q = camera.get("cam_from_rig_rotation", [1, 0, 0, 0])
        t = camera.get("cam_from_rig_translation", [0, 0, 0])
        params = [f, f, c, c, *KB_COEFFICIENTS]
        lines.append(" ".join(
            [camera["image_prefix"].rstrip("/"), "OPENCV_FISHEYE",
             str(lens_size), str(lens_size), *("%.17g" % v for v in params),
             "|", *("%.17g" % v for v in (*q, *t)),
             "%.17g" % half_field_deg]))
    with open(path, "w") as f_out:
        f_out.write("\n".join(lines) + "\n")


def rough_start(model, width, height, circle_radius, half_field_deg):
    """Parameters of MODEL that a user has from a spec sheet: the principal
    point at the image centre and the focal length that puts the edge of
    the field on the image circle, the model's generic fisheye shape (EUCM
    alpha 0.5, beta 1; DOUBLE_SPHERE xi 0, alpha 0.5: both r = 2 f tan(t/2);
    UNIFIED_OMNI xi 1 without distortion: r = f tan(t/2); OPENCV_FISHEYE
    without distortion: the equidistant r = f t)."""
    import math
    half_tan = math.tan(math.radians(half_field_deg) / 2)
    cx, cy = width / 2.0, height / 2.0
    if model == "OPENCV_FISHEYE":
        f = circle_radius / math.radians(half_field_deg)
        return [f, f, cx, cy, 0.0, 0.0, 0.0, 0.0]
    if model == "UNIFIED_OMNI":
        f = circle_radius / half_tan
        return [f, f, cx, cy, 1.0, 0.0, 0.0, 0.0, 0.0]
    f = circle_radius / (2 * half_tan)
    if model == "EUCM":
        return [f, f, cx, cy, 0.5, 1.0]
    if model == "DOUBLE_SPHERE":
        return [f, f, cx, cy, 0.0, 0.5]
    raise ValueError(f"--fit_model {model}: one of EUCM, DOUBLE_SPHERE, "
                     "UNIFIED_OMNI, OPENCV_FISHEYE")


def fitted_rig_config(scene, path, model, half_field_deg, spec=False):
    """The scene's rig_config.json with zero offsets and every lens started
    from MODEL's rough parameters (rough_start) on its image circle; SPEC:
    from the lens's field of view and image circle instead, which
    rig_configurator turns into MODEL fitted to the equidistant lens of that
    circle (as `colmap rig_preset` starts a known camera's lenses)."""
    import json
    with open(os.path.join(scene, "rig_config.json")) as f:
        config = common.without_rig_offsets(json.load(f))
    circles = {}
    with open(os.path.join(scene, "circles.txt")) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                name, cx, cy, radius = line.split()
                circles[name] = (float(cx), float(cy), float(radius))
    _, width, height, _ = next(iter(common.read_text_cameras(
        os.path.join(scene, "sparse_gt")).values()))
    for rig in config:
        for camera in rig["cameras"]:
            lens = camera["image_prefix"].rstrip("/")
            camera["camera_model_name"] = model
            if spec:
                camera.pop("camera_params", None)
                camera["field_of_view_deg"] = 2 * half_field_deg
                camera["image_circle"] = list(circles[lens])
            else:
                camera["camera_params"] = rough_start(
                    model, width, height, circles[lens][2], half_field_deg)
    with open(path, "w") as f:
        json.dump(config, f, indent=1)


def run_system(scene, preset, system, work, program, num_lenses,
               start=(1.0, False), fit_model="", reuse="", mapper_args=(),
               spec_start=False):
    """Reconstructs SCENE with SYSTEM; returns a row of results. REUSE: an
    earlier run's folder whose database (features, rig, matches) is mapped
    again instead of extracting and matching. MAPPER_ARGS: further options
    of `colmap mapper`. SPEC_START: FIT_MODEL starts from the lenses' field
    of view and image circle (fitted_rig_config)."""
    import json
    os.makedirs(work)
    logs = os.path.join(work, "logs")
    os.makedirs(logs)
    database = os.path.join(work, "database.db")
    row = {"preset": preset, "system": system}
    extraction = ["--FeatureExtraction.use_gpu", "0"]
    with open(os.path.join(scene, "rig_config.json")) as f:
        lens0 = json.load(f)[0]["cameras"][0]
    if reuse:
        earlier = os.path.join(reuse, "database.db")
        if not os.path.exists(earlier):
            raise RuntimeError(f"no database to reuse at {earlier}")
        shutil.copyfile(earlier, database)
        for suffix in ("-wal", "-shm"):  # a database left in WAL mode
            if os.path.exists(earlier + suffix):
                shutil.copyfile(earlier + suffix, database + suffix)
        image_path = os.path.join(scene, "stitched", "images") \
            if system.startswith("stitched") else os.path.join(scene, "images")
        t_extract = t_match = 0.0
        if system == "rig" and fit_model:
            # The same features and verified matches, the lenses started
            # again from FIT_MODEL's rough parameters.
            config = os.path.join(work, "rig_config.json")
            fitted_rig_config(scene, config, fit_model,
                              PRESET_HALF_FIELD_DEG[preset], spec_start)
            timed(program, ["rig_configurator", "--database_path", database,
                            "--rig_config_path", config],
                  os.path.join(logs, "rig.log"))
    elif system == "rig":
        image_path = os.path.join(scene, "images")
        t_extract = timed(program, [
            "feature_extractor", "--database_path", database, "--image_path",
            image_path, "--ImageReader.camera_model",
            fit_model or lens0["camera_model_name"],
            "--ImageReader.single_camera_per_folder", "1",
            "--ImageReader.mask_path", os.path.join(scene, "masks"),
            *extraction], os.path.join(logs, "extract.log"))
        config = os.path.join(work, "rig_config.json")
        if fit_model:
            fitted_rig_config(scene, config, fit_model,
                              PRESET_HALF_FIELD_DEG[preset], spec_start)
        else:
            rough_rig_config(scene, config, *start)
        t_extract += timed(program, [
            "rig_configurator", "--database_path", database,
            "--rig_config_path", config], os.path.join(logs, "rig.log"))
    elif system == "one_lens":
        image_path = os.path.join(scene, "images")
        list_path = os.path.join(work, "images.txt")
        with open(list_path, "w") as f:
            for name in sorted(os.listdir(os.path.join(image_path, "lens0"))):
                f.write(f"lens0/{name}\n")
        t_extract = timed(program, [
            "feature_extractor", "--database_path", database, "--image_path",
            image_path, "--image_list_path", list_path,
            "--ImageReader.camera_model", lens0["camera_model_name"],
            "--ImageReader.camera_params",
            ",".join("%.17g" % p for p in lens0["camera_params"]),
            "--ImageReader.single_camera", "1",
            "--ImageReader.mask_path", os.path.join(scene, "masks"),
            *extraction], os.path.join(logs, "extract.log"))
    else:
        image_path = os.path.join(scene, "stitched", "images")
        t_extract = timed(program, [
            "feature_extractor", "--database_path", database, "--image_path",
            image_path, "--ImageReader.camera_model", "EQUIRECTANGULAR",
            "--ImageReader.single_camera", "1", *extraction],
            os.path.join(logs, "extract.log"))
    if not reuse:
        t_match = timed(program, ["exhaustive_matcher", "--database_path",
                                  database, "--FeatureMatching.use_gpu", "0"],
                        os.path.join(logs, "match.log"))
    sparse = os.path.join(work, "sparse")
    os.makedirs(sparse)
    t_map = timed(program, ["mapper", "--database_path", database,
                            "--image_path", image_path, "--output_path",
                            sparse, *mapper_args],
                  os.path.join(logs, "map.log"))
    row.update(t_extract_s=t_extract, t_match_s=t_match, t_map_s=t_map,
               t_total_s=t_extract + t_match + t_map)
    models = sorted(os.listdir(sparse))
    row["models"] = len(models)
    if not models:
        row["error"] = "no model"
        return row
    # The model with the most images.
    best, best_count = None, -1
    for model in models:
        text = os.path.join(work, "text_" + model)
        common.model_to_text(os.path.join(sparse, model), text)
        count = len(common.read_text_images(text))
        if count > best_count:
            best, best_count = text, count
    kind = "rig" if system == "rig" else (
        "one_lens" if system == "one_lens" else "stitched")
    gt_dir = os.path.join(scene, "stitched", "sparse_gt") \
        if kind == "stitched" else os.path.join(scene, "sparse_gt")
    if kind == "one_lens":
        gt = _lens_poses(gt_dir, "lens0")
        est = _lens_poses(best, "lens0")
    else:
        gt = frame_poses(gt_dir, "rig" if kind == "rig" else "single",
                         num_lenses)
        est = frame_poses(best, "rig" if kind == "rig" else "single",
                          num_lenses)
    errors = common.aligned_pose_errors(gt, est)
    row["frames"] = len(gt)
    row["registered"] = len(errors)
    if errors:
        rotations = sorted(e[0] for e in errors.values())
        positions = sorted(e[1] for e in errors.values())
        row.update(rot_median_deg=common.median(rotations),
                   rot_max_deg=rotations[-1],
                   pos_median_mm=1000 * common.median(positions),
                   pos_max_mm=1000 * positions[-1])
    if kind == "rig":
        rig = common.rig_errors(os.path.join(scene, "sparse_gt"), best)
        if rig:
            row["rig_rot_max_deg"] = max(r for r, _ in rig.values())
            row["rig_pos_max_mm"] = 1000 * max(c for _, c in rig.values())
    return row


def _lens_poses(model_path, lens):
    """{frame: (R, centre)} of the images of one lens of a text model."""
    return {frame_of(name): pose
            for name, pose in common.text_model_poses(model_path).items()
            if name.startswith(lens + "/")}


COLUMNS = ["preset", "system", "seed", "frames", "registered", "models",
           "rot_median_deg", "rot_max_deg", "pos_median_mm", "pos_max_mm",
           "rig_rot_max_deg", "rig_pos_max_mm", "t_extract_s", "t_match_s",
           "t_map_s", "t_total_s", "error"]
SPREAD = ["rot_median_deg", "pos_median_mm", "pos_max_mm", "rig_rot_max_deg",
          "rig_pos_max_mm", "t_total_s"]


def summarize(runs):
    groups = {}
    for run in runs:
        groups.setdefault((run["preset"], run["system"]), []).append(run)
    summary = []
    for (preset, system), rows in groups.items():
        out = {"preset": preset, "system": system, "runs": len(rows),
               "failed": sum(1 for r in rows if r.get("error"))}
        out.update(common.medians_and_spreads(rows, COLUMNS[3:-1], SPREAD))
        summary.append(out)
    # Ratios of every system's median position and rotation error to the
    # rig's of the same preset.
    for row in summary:
        rig = next((r for r in summary if r["preset"] == row["preset"]
                    and r["system"] == "rig"), None)
        for key in ("pos_median_mm", "rot_median_deg", "t_total_s"):
            if rig and rig.get(key) and row.get(key) is not None:
                row[key + "_vs_rig"] = row[key] / rig[key]
    return summary


def fmt(value, digits=3):
    if value is None or value == "":
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


def spread_cell(row, key):
    """'median [min..max]' of KEY in a summary ROW, or the value alone."""
    if key + "_min" in row:
        return (f"{fmt(row.get(key))} [{fmt(row[key + '_min'])}.."
                f"{fmt(row[key + '_max'])}]")
    return fmt(row.get(key))


def print_table(summary):
    header = ["preset", "system", "reg/frames", "rot med deg", "pos med mm",
              "pos max mm", "rig rot deg", "rig pos mm", "time s",
              "pos / rig"]
    lines = [header]
    for row in summary:
        def cell(key):
            return spread_cell(row, key)
        lines.append([row["preset"], row["system"],
                      f"{fmt(row.get('registered'))}/{fmt(row.get('frames'))}",
                      cell("rot_median_deg"), cell("pos_median_mm"),
                      cell("pos_max_mm"), cell("rig_rot_max_deg"),
                      cell("rig_pos_max_mm"), cell("t_total_s"),
                      fmt(row.get("pos_median_mm_vs_rig"))])
    widths = [max(len(str(line[i])) for line in lines)
              for i in range(len(header))]
    for line in lines:
        print("  ".join(str(v).ljust(w) for v, w in zip(line, widths)))


def write_csv(path, rows):
    keys = []
    for row in rows:
        keys += [k for k in row if k not in keys]
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=keys)
        writer.writeheader()
        writer.writerows(rows)


def write_png(path, summary):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    presets = sorted({r["preset"] for r in summary})
    systems = ["rig", "stitched", "stitched_upstream", "one_lens"]
    colours = {"rig": "tab:green", "stitched": "tab:orange",
               "stitched_upstream": "tab:red", "one_lens": "tab:blue"}
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    for ax, key, title in zip(
            axes, ("pos_median_mm", "rot_median_deg", "t_total_s"),
            ("position error (median over frames), mm",
             "rotation error (median over frames), deg",
             "time of the pipeline, s")):
        width = 0.8 / len(systems)
        for s, system in enumerate(systems):
            xs, ys, lo, hi = [], [], [], []
            for p, preset in enumerate(presets):
                row = next((r for r in summary if r["preset"] == preset
                            and r["system"] == system), None)
                if not row or row.get(key) is None:
                    continue
                xs.append(p + (s - 1.5) * width)
                ys.append(row[key])
                lo.append(row[key] - row.get(key + "_min", row[key]))
                hi.append(row.get(key + "_max", row[key]) - row[key])
            if xs:
                ax.bar(xs, ys, width, yerr=[lo, hi], capsize=3,
                       color=colours[system], label=system)
        ax.set_xticks(range(len(presets)))
        ax.set_xticklabels(presets)
        if key != "t_total_s":
            ax.set_yscale("log")
        ax.set_title(title, fontsize=10)
    axes[0].legend(fontsize=8)
    fig.suptitle("Raw rig vs stitched panorama vs one lens: median and "
                 "min..max over seeds")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def add_program_arguments(parser):
    """--colmap and --render: the programs of the build by default."""
    parser.add_argument("--colmap", default=os.path.join(REPO, "build", "bin",
                                                         "colmap"))
    parser.add_argument("--render", default=os.path.join(
        REPO, "build", "synthetic", "sphera_render"))


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    parser.add_argument("--repeats", type=int, default=3,
                        help="seeds 0..N-1: each renders its own scene")
    parser.add_argument("--first_seed", type=int, default=0,
                        help="seeds first_seed .. first_seed + repeats - 1 "
                             "(to add seeds to an earlier output)")
    parser.add_argument("--presets", default="dual_fisheye,ring8")
    parser.add_argument("--systems",
                        default="rig,stitched,stitched_upstream,one_lens")
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--lens_size", type=int, default=0,
                        help="pixels of a lens image (0: the preset's)")
    parser.add_argument("--stitched_width", type=int, default=2048)
    parser.add_argument("--start_focal_scale", type=float, default=1.0,
                        help="the rig's start: focal lengths times this")
    parser.add_argument("--start_no_distortion", action="store_true",
                        help="the rig's start: distortion unknown "
                             "(sphera_common.rough_intrinsics)")
    parser.add_argument("--lens", choices=("preset", "kb"), default="preset",
                        help="kb: lenses drawn through a Kannala-Brandt "
                             "polynomial, not a fitted model")
    parser.add_argument("--realistic", action="store_true",
                        help="sphera_render's sensor effects")
    common.add_render_option_argument(parser)
    parser.add_argument("--fit_model", default="",
                        help="the rig starts from this model's rough "
                             "parameters (EUCM, DOUBLE_SPHERE, UNIFIED_OMNI, "
                             "OPENCV_FISHEYE)")
    parser.add_argument("--start", choices=("generic", "spec"),
                        default="generic",
                        help="with --fit_model: generic, the model's generic "
                             "fisheye shape through the image circle "
                             "(rough_start); spec, the field of view and the "
                             "image circle in the rig config, from which "
                             "rig_configurator fits the model to the "
                             "equidistant lens")
    parser.add_argument("--supersample", type=int, default=2,
                        help="rays per pixel side of the renders")
    parser.add_argument("--output", default=os.path.join(REPO, "build",
                                                         "bench_rig"))
    parser.add_argument("--reuse_database", default="",
                        help="an earlier --output of the same scenes: each "
                             "run maps that run's database again (mapping "
                             "alone; scenes missing here are rendered again "
                             "for their ground truth)")
    parser.add_argument("--mapper_args", default="",
                        help="further options of `colmap mapper`, e.g. "
                             "\"--Mapper.hold_rig_intrinsics_frames 3\"")
    add_program_arguments(parser)
    parser.add_argument("--upstream_colmap", default=common.UPSTREAM_COLMAP)
    parser.add_argument("--no_upstream", action="store_true")
    args = parser.parse_args()

    systems = args.systems.split(",")
    if args.no_upstream and "stitched_upstream" in systems:
        systems.remove("stitched_upstream")
    if "stitched_upstream" in systems and not os.path.exists(
            args.upstream_colmap):
        sys.exit(f"benchmark_rig: no upstream COLMAP at "
                 f"{args.upstream_colmap} (../shared/peers/build_colmap4.sh "
                 f"builds it; or --no_upstream)")
    for path in (args.colmap, args.render):
        if not os.path.exists(path):
            sys.exit(f"benchmark_rig: {path} is missing (scripts/build.sh)")
    os.makedirs(args.output, exist_ok=True)
    seeds = range(args.first_seed, args.first_seed + args.repeats)
    # model_to_text and friends run this colmap.
    common.COLMAP = args.colmap
    # Runs of an earlier call into the same output that this one does not
    # repeat are kept (e.g. --systems one_lens after a full run).
    runs_csv = os.path.join(args.output, "rig_runs.csv")
    runs = common.earlier_runs(
        runs_csv, lambda row: row.get("system") in systems
        and row.get("seed") in seeds
        and row.get("preset") in args.presets.split(","))
    for seed in seeds:
        for preset in args.presets.split(","):
            scene = os.path.join(args.output, f"scene_{preset}_{seed}")
            if not os.path.exists(os.path.join(scene, "sparse_gt")):
                shutil.rmtree(scene, ignore_errors=True)
                render = ["--frames", args.frames, "--seed", seed,
                          "--supersample", args.supersample]
                if args.lens == "kb":
                    # The preset's lens poses, from a one-frame render.
                    import json
                    layout = scene + "_layout"
                    shutil.rmtree(layout, ignore_errors=True)
                    common.run_render(layout, "--rig_preset", preset,
                                      "--frames", 1, "--lens_size", 64,
                                      "--supersample", 1, program=args.render)
                    with open(os.path.join(layout, "rig_config.json")) as f:
                        layout_config = json.load(f)
                    shutil.rmtree(layout, ignore_errors=True)
                    sensors = scene + "_sensors.txt"
                    kb_sensors_file(layout_config, args.lens_size or 640,
                                    PRESET_HALF_FIELD_DEG[preset], sensors)
                    render += ["--rig_sensors", sensors]
                else:
                    render += ["--rig_preset", preset]
                    if args.lens_size:
                        render += ["--lens_size", args.lens_size]
                if args.realistic:
                    render += ["--realistic"]
                render += common.render_options(args)
                if preset == "dual_fisheye":
                    render += ["--stitched", "--stitched_width",
                               args.stitched_width]
                log(f"render {preset} seed {seed}")
                common.run_render(scene, *render, program=args.render)
            num_lenses = len(common.read_text_cameras(
                os.path.join(scene, "sparse_gt")))
            for system in systems:
                if system.startswith("stitched") and preset != "dual_fisheye":
                    continue
                program = args.upstream_colmap \
                    if system == "stitched_upstream" else args.colmap
                work = os.path.join(args.output, f"run_{preset}_{system}_{seed}")
                shutil.rmtree(work, ignore_errors=True)
                log(f"{preset} {system} seed {seed}")
                try:
                    row = run_system(scene, preset, system, work, program,
                                     num_lenses, (args.start_focal_scale,
                                                  args.start_no_distortion),
                                     args.fit_model,
                                     os.path.join(args.reuse_database,
                                                  os.path.basename(work))
                                     if args.reuse_database else "",
                                     shlex.split(args.mapper_args),
                                     args.start == "spec")
                except (RuntimeError, OSError, ValueError) as error:
                    row = {"preset": preset, "system": system,
                           "error": str(error).splitlines()[0]}
                row["seed"] = seed
                log("  " + ", ".join(f"{k}={fmt(v)}" for k, v in row.items()
                                     if k not in ("preset", "system")))
                runs.append(row)
                write_csv(runs_csv, runs)
    summary = summarize(runs)
    write_csv(os.path.join(args.output, "rig_results.csv"), summary)
    write_png(os.path.join(args.output, "rig_results.png"), summary)
    print_table(summary)
    print(f"\nwrote {args.output}/rig_runs.csv, rig_results.csv, "
          f"rig_results.png")


if __name__ == "__main__":
    main()
