#!/usr/bin/python3
"""The incremental mapper's initial-pair search on rig frames: its share of
the mapping time, for this build's colmap and another one (--before: the
program of an earlier commit, e.g. a build of the parent commit's worktree)
on the same databases, with the same seeds.

Each seed renders the 8-lens ring (sphera_render --rig_preset ring8, 640-px
lenses, rig_ring_test's scene) or the dual-fisheye rig, extracts one EUCM
camera per lens with the image-circle masks, configures the rig as a user
knows it (the lenses' directions and intrinsics, every offset zero) and
matches exhaustively, once. Then `colmap mapper` runs with each program
(--Mapper.random_seed SEED), and its log gives the search time: from each
"Finding good initial image pair" to the search's result, summed over the
relaxations and the models; the mapping time is the mapper's wall time.

Usage (from the repository root, after scripts/build.sh):
  scripts/benchmark_initial_pair.py --before OTHER/build/bin/colmap
  scripts/benchmark_initial_pair.py --seeds 3 --preset dual_fisheye
Output (--output, default build/bench_initial_pair): initial_pair.csv (one
row per program and seed), initial_pair.png, logs/.
"""
import argparse
import datetime
import json
import os
import re
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sphera_common as common  # noqa: E402
from benchmark_rig import (add_program_arguments, log, timed,  # noqa: E402
                           write_csv)

FRAMES = 6
LENS_SIZE = 640
SEARCH_START = "Finding good initial image pair"
SEARCH_ENDS = ("Registering initial image pair", "No good initial image pair")
TIME = re.compile(r"^[IWE]\d{8} (\d\d):(\d\d):(\d\d\.\d+)")


def log_seconds(line):
    """Seconds of the day of a COLMAP (glog) log line, or None."""
    match = TIME.match(line)
    if not match:
        return None
    hours, minutes, seconds = match.groups()
    return 3600 * int(hours) + 60 * int(minutes) + float(seconds)


def search_seconds(log_path):
    """(seconds in the initial-pair search, number of searches) of a mapper
    log."""
    total = 0.0
    searches = 0
    start = None
    with open(log_path, errors="replace") as f:
        for line in f:
            if SEARCH_START in line:
                start = log_seconds(line)
                searches += 1
            elif start is not None and any(end in line for end in SEARCH_ENDS):
                end = log_seconds(line)
                total += (end - start) % 86400
                start = None
    return total, searches


def prepare(work, colmap, render, preset, seed):
    """The configured, matched database of SEED's scene and its images."""
    scene = os.path.join(work, f"scene{seed}")
    database = os.path.join(work, f"matched{seed}.db")
    logs = os.path.join(work, "logs")
    os.makedirs(logs, exist_ok=True)
    common.run_render(scene, "--rig_preset", preset, "--frames", FRAMES,
                      "--lens_size", LENS_SIZE, "--supersample", 2,
                      "--seed", seed, program=render)
    images = os.path.join(scene, "images")
    timed(colmap, ["feature_extractor", "--database_path", database,
                   "--image_path", images, "--ImageReader.camera_model",
                   "EUCM", "--ImageReader.mask_path",
                   os.path.join(scene, "masks"),
                   "--ImageReader.single_camera_per_folder", "1",
                   *common.CPU_EXTRACTION],
          os.path.join(logs, f"extract{seed}.log"))
    with open(os.path.join(scene, "rig_config.json")) as f:
        config = common.without_rig_offsets(json.load(f))
    config_path = os.path.join(work, f"rig_config{seed}.json")
    with open(config_path, "w") as f:
        json.dump(config, f)
    timed(colmap, ["rig_configurator", "--database_path", database,
                   "--rig_config_path", config_path],
          os.path.join(logs, f"configure{seed}.log"))
    timed(colmap, ["exhaustive_matcher", "--database_path", database,
                   *common.CPU_MATCHING],
          os.path.join(logs, f"match{seed}.log"))
    return database, images


def map_once(work, program, name, database, images, seed):
    """One mapper run of PROGRAM on a copy of DATABASE: a result row."""
    run = os.path.join(work, f"{name}_{seed}")
    shutil.rmtree(run, ignore_errors=True)
    os.makedirs(os.path.join(run, "sparse"))
    copy = os.path.join(run, "database.db")
    shutil.copy(database, copy)
    log_path = os.path.join(work, "logs", f"map_{name}_{seed}.log")
    code, seconds = common.run_logged(
        [program, "mapper", "--database_path", copy, "--image_path", images,
         "--output_path", os.path.join(run, "sparse"),
         "--Mapper.random_seed", str(seed)], log_path, 3600)
    search, searches = search_seconds(log_path)
    registered = 0
    for model in sorted(os.listdir(os.path.join(run, "sparse"))):
        path = os.path.join(run, "sparse", model)
        if os.path.isdir(path):
            registered = max(registered, common.model_counts(path)[0])
    return {"program": name, "seed": seed, "exit": code,
            "mapping_s": round(seconds, 2), "search_s": round(search, 2),
            "searches": searches,
            "search_share": round(search / seconds, 4) if seconds else None,
            "registered": registered}


def write_png(path, rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = sorted({r["program"] for r in rows})
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, key, title in zip(axes, ("search_s", "search_share"),
                              ("initial-pair search, s",
                               "share of the mapping time")):
        ax.boxplot([[r[key] for r in rows if r["program"] == n]
                    for n in names], labels=names)
        ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--preset", default="ring8")
    parser.add_argument("--before", help="another colmap to compare with")
    parser.add_argument("--output", default=os.path.join(
        common.REPO_ROOT, "build", "bench_initial_pair"))
    add_program_arguments(parser)
    args = parser.parse_args()
    programs = [("this", args.colmap)]
    if args.before:
        programs.append(("before", args.before))
    os.makedirs(args.output, exist_ok=True)
    rows = []
    for seed in range(args.seeds):
        log(f"seed {seed}: rendering, extracting, matching")
        database, images = prepare(args.output, args.colmap, args.render,
                                   args.preset, seed)
        for name, program in programs:
            row = map_once(args.output, program, name, database, images, seed)
            log(f"seed {seed} {name}: {row}")
            rows.append(row)
    write_csv(os.path.join(args.output, "initial_pair.csv"), rows)
    write_png(os.path.join(args.output, "initial_pair.png"), rows)
    print(f"\n{args.preset}, {FRAMES} frames, {LENS_SIZE}-px lenses, "
          f"{args.seeds} seeds ({datetime.date.today()})")
    print(f"{'program':8} {'registered':>10} {'search s (median, range)':>26}"
          f" {'share (median, range)':>24} {'mapping s':>10}")
    for name, _ in programs:
        mine = [r for r in rows if r["program"] == name]
        search = [r["search_s"] for r in mine]
        share = [r["search_share"] for r in mine]
        print(f"{name:8} {'/'.join(str(r['registered']) for r in mine):>10} "
              f"{common.median(search):8.2f} ({min(search):.2f}-"
              f"{max(search):.2f}) {100 * common.median(share):12.1f}% "
              f"({100 * min(share):.1f}-{100 * max(share):.1f}%) "
              f"{common.median([r['mapping_s'] for r in mine]):10.1f}")


if __name__ == "__main__":
    main()
