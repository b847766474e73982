"""Helpers shared by the integration tests (tests/) and the benchmark scripts:
COLMAP text models, quaternions and rotations, running `colmap` and the
renderer sphera_render, and the camera rigs of the rendered sets.

Standard library only; the functions that need numpy import it themselves,
so that a script that does not use them starts without it."""
import csv
import hashlib
import math
import os
import re
import shutil
import struct
import subprocess
import tempfile
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The shared data set beside the repository (strecha/, equirect_flat/, ...).
SHARED_DATA_DIR = os.path.join(REPO_ROOT, "..", "shared", "data")
# Unpatched upstream COLMAP 4.x where ../shared/peers/build_colmap4.sh
# builds it.
UPSTREAM_COLMAP = os.path.join(os.path.expanduser("~"), ".cache",
                               "sphera-peers", "colmap4", "build", "src",
                               "colmap", "exe", "colmap")

# The programs the tests run: the built colmap and sphera_render.
COLMAP = os.environ.get("SPHERA_COLMAP", "")
RENDER = os.environ.get("SPHERA_RENDER", "")

# Prefixes of COLMAP 4.x's feature extraction and matching options
# (--FeatureExtraction.*, --FeatureMatching.*).
EXTRACTION = "FeatureExtraction"
MATCHING = "FeatureMatching"
# Feature extraction and matching on the CPU.
CPU_EXTRACTION = [f"--{EXTRACTION}.use_gpu", "0"]
CPU_MATCHING = [f"--{MATCHING}.use_gpu", "0"]


# ---------------------------------------------------------------------------
# COLMAP text models


def read_text_rows(path):
    """Fields of the lines of a text file that are neither comments nor
    empty."""
    with open(path) as f:
        return [line.split() for line in f
                if not line.startswith("#") and line.strip()]


def read_text_cameras(path):
    """{camera_id: (model name, width, height, [params])} of
    PATH/cameras.txt."""
    return {int(fields[0]): (fields[1], int(fields[2]), int(fields[3]),
                             [float(v) for v in fields[4:]])
            for fields in read_text_rows(os.path.join(path, "cameras.txt"))}


def read_text_images(path):
    """{image_id: (header fields, [(x, y, point3D_id)])} of PATH/images.txt.
    A header has 10 fields and a POINTS2D line a multiple of 3: a header
    without its POINTS2D line is an image without observations."""
    images = {}
    header = None
    with open(os.path.join(path, "images.txt")) as f:
        for line in f:
            if line.startswith("#"):
                continue
            values = line.split()
            if header is None or len(values) == 10:
                if header is not None:
                    images[int(header[0])] = (header, [])
                header = values or None
                continue
            images[int(header[0])] = (header, [
                (float(values[i]), float(values[i + 1]), int(values[i + 2]))
                for i in range(0, len(values), 3)])
            header = None
    if header is not None:
        images[int(header[0])] = (header, [])
    return images


def read_text_points(path):
    """{point3D_id: ((x, y, z), [(image_id, point2D_idx)])} of
    PATH/points3D.txt."""
    points = {}
    for fields in read_text_rows(os.path.join(path, "points3D.txt")):
        track = [(int(fields[i]), int(fields[i + 1]))
                 for i in range(8, len(fields), 2)]
        points[int(fields[0])] = (tuple(float(v) for v in fields[1:4]), track)
    return points


def read_text_model(path):
    """(cameras {id: (model, width, height, params)},
        images {id: (header fields, [(x, y, point3D_id)])},
        points {id: ((x, y, z), [(image_id, point2D_idx)])})."""
    return (read_text_cameras(path), read_text_images(path),
            read_text_points(path))


def model_counts(model_dir):
    """(registered images, points) of a COLMAP binary or text model; None
    when MODEL_DIR holds neither."""
    images_bin = os.path.join(model_dir, "images.bin")
    if os.path.exists(images_bin):
        counts = []
        for name in ("images.bin", "points3D.bin"):
            with open(os.path.join(model_dir, name), "rb") as f:
                counts.append(struct.unpack("<Q", f.read(8))[0])
        return tuple(counts)
    if os.path.exists(os.path.join(model_dir, "images.txt")):
        return (len(read_text_images(model_dir)),
                len(read_text_rows(os.path.join(model_dir, "points3D.txt"))))
    return None


def params_text(params):
    """Camera parameters as --ImageReader.camera_params takes them: comma
    separated, whole numbers without a decimal point."""
    return ",".join(str(int(p)) if float(p).is_integer() else repr(float(p))
                    for p in params)


# ---------------------------------------------------------------------------
# Quaternions (w, x, y, z) and rotation matrices (nested lists, or numpy
# where said)


def quat_mul(a, b):
    """The quaternion product a b."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw)


def quat_rotate(q, v):
    """v rotated by the unit quaternion q."""
    w, x, y, z = quat_mul(quat_mul(q, (0.0, *v)), (q[0], -q[1], -q[2], -q[3]))
    return (x, y, z)


def axis_angle_quat(axis, angle):
    """The unit quaternion of a rotation by ANGLE (radians) about AXIS."""
    norm = math.sqrt(sum(a * a for a in axis))
    s = math.sin(angle / 2) / norm
    return (math.cos(angle / 2), axis[0] * s, axis[1] * s, axis[2] * s)


def rotation_matrix(qw, qx, qy, qz):
    """Rotation matrix (nested lists) of a unit quaternion (w, x, y, z)."""
    w, x, y, z = qw, qx, qy, qz
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def rotation_from_quaternion(qw, qx, qy, qz):
    """Rotation matrix (numpy) of a unit quaternion (w, x, y, z)."""
    import numpy as np
    return np.array(rotation_matrix(qw, qx, qy, qz))


def quaternion_from_matrix(r):
    """(w, x, y, z), w >= 0, of a rotation matrix."""
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


def axis_rotation(axis, angle):
    """Rotation matrix by ANGLE (radians) about axis 0 (x), 1 (y) or 2 (z)."""
    c, s = math.cos(angle), math.sin(angle)
    if axis == 0:
        return [[1, 0, 0], [0, c, -s], [0, s, c]]
    if axis == 1:
        return [[c, 0, s], [0, 1, 0], [-s, 0, c]]
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]]


def matmul(a, b):
    """The 3 x 3 matrix product a b."""
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)]
            for i in range(3)]


def transpose(m):
    """The transpose of a 3 x 3 matrix."""
    return [[m[j][i] for j in range(3)] for i in range(3)]


def mat_vec(m, v):
    """The 3 x 3 matrix m times the vector v."""
    return [sum(m[i][k] * v[k] for k in range(3)) for i in range(3)]


# ---------------------------------------------------------------------------
# Camera poses of text models, and their errors against a ground truth


def cam_from_world(fields):
    """(rotation, translation) (numpy) of an images.txt header's fields."""
    import numpy as np
    rotation = rotation_from_quaternion(*map(float, fields[1:5]))
    return rotation, np.array([float(v) for v in fields[5:8]])


def text_model_poses(path):
    """{image name: (R cam_from_world, camera centre)} of a text model."""
    poses = {}
    for fields, _ in read_text_images(path).values():
        rotation, translation = cam_from_world(fields)
        poses[fields[9]] = (rotation, -rotation.T @ translation)
    return poses


def similarity_of_centres(est_centres, gt_centres):
    """(scale, rotation, translation) of the least-squares similarity
    gt = scale rotation est + translation of two (N, 3) arrays of camera
    centres (Umeyama 1991)."""
    import numpy as np
    gt_mean, est_mean = gt_centres.mean(0), est_centres.mean(0)
    gt_d, est_d = gt_centres - gt_mean, est_centres - est_mean
    u, singular, vt = np.linalg.svd(gt_d.T @ est_d / len(gt_centres))
    sign = np.eye(3)
    if np.linalg.det(u @ vt) < 0:
        sign[2, 2] = -1
    rotation = u @ sign @ vt
    scale = np.trace(np.diag(singular) @ sign) / (est_d ** 2).sum(1).mean()
    return scale, rotation, gt_mean - scale * rotation @ est_mean


def aligned_pose_errors(gt, est):
    """{name: (rotation error in degrees, position error)} of the poses
    {name: (R cam_from_world, position)} of EST against GT, for the names of
    both, after the least-squares similarity of the positions (Umeyama
    1991): ||log(R_gt R_est^T)|| and the distance of the aligned positions.
    Empty with fewer than 3 common names."""
    import numpy as np
    names = sorted(set(gt) & set(est))
    if len(names) < 3:
        return {}
    scale, gt_from_est, translation = similarity_of_centres(
        np.array([est[n][1] for n in names]),
        np.array([gt[n][1] for n in names]))
    errors = {}
    for name in names:
        centre = scale * gt_from_est @ est[name][1] + translation
        # est cam_from_world composed with est_from_gt maps gt world to cam.
        relative = gt[name][0] @ (est[name][0] @ gt_from_est.T).T
        angle = np.arccos(np.clip((np.trace(relative) - 1) / 2, -1, 1))
        errors[name] = (float(np.degrees(angle)),
                        float(np.linalg.norm(centre - gt[name][1])))
    return errors


def pose_errors(gt_path, model_path):
    """aligned_pose_errors of the images of the text models at GT_PATH and
    MODEL_PATH (camera centres and orientations)."""
    return aligned_pose_errors(text_model_poses(gt_path),
                               text_model_poses(model_path))


def read_text_rigs(path):
    """{rig_id: {camera_id: (R sensor_from_rig, t) or None}} of
    PATH/rigs.txt (COLMAP 4 text), the reference sensor with the identity;
    sensors that are not cameras are left out."""
    import numpy as np
    rigs = {}
    for fields in read_text_rows(os.path.join(path, "rigs.txt")):
        sensors = {}
        if int(fields[1]) > 0:
            if fields[2] == "CAMERA":
                sensors[int(fields[3])] = (np.eye(3), np.zeros(3))
            rest = fields[4:]
            while rest:
                has_pose = rest[2] == "1"
                pose = None
                if has_pose:
                    q = [float(v) for v in rest[3:7]]
                    pose = (rotation_from_quaternion(*q),
                            np.array([float(v) for v in rest[7:10]]))
                if rest[0] == "CAMERA":
                    sensors[int(rest[1])] = pose
                rest = rest[10:] if has_pose else rest[3:]
        rigs[int(fields[0])] = sensors
    return rigs


def sensors_by_folder(path):
    """{image folder: (R sensor_from_rig, t)} of the text model at PATH: the
    pose in its rig of every camera, named by the folder of its images (a
    rig's lens images are FOLDER/NAME)."""
    camera_folder = {}
    for fields, _ in read_text_images(path).values():
        camera_folder.setdefault(int(fields[8]), fields[9].split("/")[0])
    sensors = {}
    for rig in read_text_rigs(path).values():
        for camera_id, pose in rig.items():
            if camera_id in camera_folder and pose is not None:
                sensors[camera_folder[camera_id]] = pose
    return sensors


def rig_frame_poses(poses, num_lenses):
    """{frame: (R cam_from_world of lens0, mean of the lens centres)} of the
    poses {'lensK/NAME': (R, centre)} of a rig model (text_model_poses), for
    the frames that hold all NUM_LENSES lenses."""
    import numpy as np
    lenses = {}
    for name, pose in poses.items():
        lens, frame = name.split("/")[0], name.split("/")[-1]
        lenses.setdefault(frame, {})[lens] = pose
    return {frame: (of_frame["lens0"][0],
                    np.mean([c for _, c in of_frame.values()], axis=0))
            for frame, of_frame in lenses.items()
            if len(of_frame) == num_lenses and "lens0" in of_frame}


def without_rig_offsets(config):
    """CONFIG (a rig_config.json list) with every non-reference lens's
    translation set to zero: what a user knows of a camera (the lenses'
    directions), not its calibration."""
    for rig in config:
        for camera in rig["cameras"]:
            if not camera.get("ref_sensor"):
                camera["cam_from_rig_translation"] = [0, 0, 0]
    return config


def rough_intrinsics(config, focal_scale=1.0, no_distortion=False):
    """CONFIG (a rig_config.json list) with every lens's focal lengths scaled
    by FOCAL_SCALE and, with NO_DISTORTION, what a user who knows only the
    kind of lens starts from: UNIFIED_OMNI's distortion coefficients zero,
    EUCM's alpha and beta those of a generic fisheye (0.5, 1: the unified
    model with xi = 1)."""
    for rig in config:
        for camera in rig["cameras"]:
            params = camera["camera_params"]
            params[0] *= focal_scale
            params[1] *= focal_scale
            if no_distortion and camera["camera_model_name"] == "UNIFIED_OMNI":
                params[5:9] = [0, 0, 0, 0]
            if no_distortion and camera["camera_model_name"] == "EUCM":
                params[4:6] = [0.5, 1]
    return config


def rig_errors(gt_path, model_path):
    """{image folder: (rotation error in degrees, centre error)} of the
    sensor_from_rig poses of the text model at MODEL_PATH against those of
    GT_PATH: the angle of R_gt R_est^T and the distance of the lens centres
    in the rig, the model's scaled to the ground truth by the similarity of
    the image centres (as pose_errors)."""
    import numpy as np
    gt = text_model_poses(gt_path)
    est = text_model_poses(model_path)
    names = sorted(set(gt) & set(est))
    scale, _, _ = similarity_of_centres(np.array([est[n][1] for n in names]),
                                        np.array([gt[n][1] for n in names]))
    gt_sensors = sensors_by_folder(gt_path)
    errors = {}
    for folder, (rotation, translation) in sensors_by_folder(
            model_path).items():
        if folder not in gt_sensors:
            continue
        gt_rotation, gt_translation = gt_sensors[folder]
        relative = gt_rotation @ rotation.T
        angle = np.arccos(np.clip((np.trace(relative) - 1) / 2, -1, 1))
        centre = -rotation.T @ translation * scale
        gt_centre = -gt_rotation.T @ gt_translation
        errors[folder] = (float(np.degrees(angle)),
                          float(np.linalg.norm(centre - gt_centre)))
    return errors


def earlier_runs(path, repeated):
    """The rows of a benchmark's runs CSV at PATH (written by an earlier call
    into the same output) for which REPEATED(row) is false, i.e. the runs this
    call does not repeat; empty cells left out, numbers as numbers."""
    if not os.path.exists(path):
        return []

    def value(text):
        for kind in (int, float):
            try:
                return kind(text)
            except ValueError:
                pass
        return text

    with open(path, newline="") as f:
        rows = [{k: value(v) for k, v in row.items() if v not in ("", None)}
                for row in csv.DictReader(f)]
    return [row for row in rows if not repeated(row)]


def medians_and_spreads(rows, keys, spread_keys):
    """{key: median} over ROWS (dicts) of every key of KEYS that some row
    holds a value of, with key_min and key_max for the keys of
    SPREAD_KEYS."""
    out = {}
    for key in keys:
        values = [float(r[key]) for r in rows if r.get(key) not in (None, "")]
        if values:
            out[key] = median(values)
            if key in spread_keys:
                out[key + "_min"] = min(values)
                out[key + "_max"] = max(values)
    return out


def median(values):
    """The median of a non-empty sequence of numbers."""
    values = sorted(values)
    middle = len(values) // 2
    if len(values) % 2:
        return values[middle]
    return (values[middle - 1] + values[middle]) / 2


# ---------------------------------------------------------------------------
# Running the programs


def run_program(program, *args, check=True, timeout=1800, name=None):
    """Runs `PROGRAM ARGS`, returns the CompletedProcess (stdout+stderr text);
    with CHECK a non-zero exit raises an AssertionError with the output's
    end, naming the program as NAME (default: PROGRAM)."""
    result = subprocess.run([program, *map(str, args)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, timeout=timeout)
    if check and result.returncode != 0:
        raise AssertionError(f"{name or program} {' '.join(map(str, args))} "
                             f"exited {result.returncode}:\n"
                             f"{result.stdout[-4000:]}")
    return result


def run_colmap(*args, check=True, timeout=1800):
    """Runs `colmap ARGS` (SPHERA_COLMAP), returns the CompletedProcess
    (stdout+stderr text)."""
    if not COLMAP or not os.path.exists(COLMAP):
        raise RuntimeError(f"SPHERA_COLMAP={COLMAP!r} is not the built colmap")
    return run_program(COLMAP, *args, check=check, timeout=timeout,
                       name="colmap")


def extract_features(database, image_path, camera_model, *options,
                     params=None, single_camera=True, program=None):
    """Runs feature_extractor on the CPU, with PROGRAM (default run_colmap):
    the images of IMAGE_PATH into DATABASE, as cameras of CAMERA_MODEL
    (PARAMS when given; one camera for all of them unless not
    SINGLE_CAMERA), with further OPTIONS. Returns PROGRAM's result."""
    command = ["feature_extractor", "--database_path", database,
               "--image_path", image_path,
               "--ImageReader.camera_model", camera_model]
    if params is not None:
        command += ["--ImageReader.camera_params", params_text(params)]
    if single_camera:
        command += ["--ImageReader.single_camera", "1"]
    return (program or run_colmap)(*command, *options, *CPU_EXTRACTION)


def match_exhaustive(database, *options, program=None):
    """Runs exhaustive_matcher on the CPU on DATABASE, with further OPTIONS,
    with PROGRAM (default run_colmap); returns PROGRAM's result."""
    return (program or run_colmap)("exhaustive_matcher", "--database_path",
                                   database, *options, *CPU_MATCHING)


def model_to_text(model_path, text_path):
    """TEXT_PATH, made to hold the model at MODEL_PATH as a text model."""
    os.makedirs(text_path)
    run_colmap("model_converter", "--input_path", model_path, "--output_path",
               text_path, "--output_type", "TXT")
    return text_path


def analyze_model(model_path):
    """(registered images, points, mean reprojection error in px) that
    `colmap model_analyzer` reports for a model."""
    analysis = run_colmap("model_analyzer", "--path", model_path).stdout
    registered = int(re.search(r"Registered images: (\d+)", analysis)[1])
    points = int(re.search(r"Points: (\d+)", analysis)[1])
    reprojection_px = float(
        re.search(r"Mean reprojection error: ([0-9.]+)px", analysis)[1])
    return registered, points, reprojection_px


def run_logged(command, log_path, timeout, **options):
    """Runs COMMAND with its output (after a line '$ COMMAND') in LOG_PATH;
    returns (exit code, seconds). OPTIONS go to subprocess.run; a timeout
    raises subprocess.TimeoutExpired."""
    start = time.monotonic()
    with open(log_path, "w") as log_file:
        log_file.write("$ " + " ".join(command) + "\n")
        log_file.flush()
        process = subprocess.run(command, stdout=log_file,
                                 stderr=subprocess.STDOUT, timeout=timeout,
                                 **options)
    return process.returncode, time.monotonic() - start


# Rendered scenes are kept between runs, as ccache keeps objects: in
# SPHERA_SCENE_CACHE (default ~/.cache/sphera/scenes; empty: no cache), at
# most SPHERA_SCENE_CACHE_MB megabytes (default 3000; the least recently
# used go first). A scene's key is the renderer's executable (its bytes:
# our libraries are linked into it statically) and its arguments, with the
# contents of every argument that names a file, so that a changed renderer
# or rig file renders afresh. The renderer is deterministic for given
# arguments (its seed is one of them) and writes no path into its output.
SCENE_CACHE = os.environ.get(
    "SPHERA_SCENE_CACHE",
    os.path.join(os.path.expanduser("~"), ".cache", "sphera", "scenes"))
SCENE_CACHE_MB = int(os.environ.get("SPHERA_SCENE_CACHE_MB", "3000"))


def _render_key(program, args):
    """The cache key of `PROGRAM --output ... ARGS`, or None when an
    argument names a folder (its contents are not hashed)."""
    digest = hashlib.sha256()
    with open(program, "rb") as f:
        digest.update(f.read())
    for arg in args:
        if os.path.isdir(arg):
            return None
        digest.update(b"\0")
        if os.path.isfile(arg):
            with open(arg, "rb") as f:
                digest.update(b"file\0" + f.read())
        else:
            digest.update(arg.encode())
    return digest.hexdigest()[:32]


def _prune_scene_cache():
    """Removes the least recently used scenes beyond SCENE_CACHE_MB."""
    entries = []
    for name in os.listdir(SCENE_CACHE):
        path = os.path.join(SCENE_CACHE, name)
        if name.startswith("tmp"):  # a render that was stopped
            if os.path.getmtime(path) < time.time() - 86400:
                shutil.rmtree(path, ignore_errors=True)
            continue
        if not os.path.isdir(path):
            continue
        size = sum(os.path.getsize(os.path.join(folder, file))
                   for folder, _, files in os.walk(path) for file in files)
        entries.append((os.path.getmtime(path), size, path))
    total = sum(size for _, size, _ in entries)
    for _, size, path in sorted(entries):
        if total <= SCENE_CACHE_MB * 1e6:
            break
        shutil.rmtree(path, ignore_errors=True)
        total -= size


def add_render_option_argument(parser):
    """--render_option OPTION=VALUE (repeatable): a sphera_render option
    after --realistic; render_options(args) gives them as arguments."""
    parser.add_argument("--render_option", action="append", default=[],
                        metavar="OPTION=VALUE",
                        help="a sphera_render option after --realistic, "
                        "e.g. --render_option=--vignetting=0 (repeatable)")


def render_options(args):
    """The sphera_render arguments of args.render_option."""
    return [part for option in args.render_option
            for part in option.split("=", 1)]


def run_render(output, *args, program=None):
    """Runs `sphera_render --output OUTPUT ARGS` (PROGRAM, default
    SPHERA_RENDER) without its output, or copies the same scene from the
    scene cache; a failure raises subprocess.CalledProcessError."""
    program = shutil.which(program or RENDER) or program or RENDER
    args = [str(arg) for arg in args]
    key = _render_key(program, args) if SCENE_CACHE else None
    cached = os.path.join(SCENE_CACHE, key) if key else None
    if cached and os.path.isdir(cached):
        os.utime(cached)
        shutil.copytree(cached, output, dirs_exist_ok=True)
        return
    if not cached:
        subprocess.run([program, "--output", output, *args], check=True,
                       stdout=subprocess.DEVNULL)
        return
    os.makedirs(SCENE_CACHE, exist_ok=True)
    staging = tempfile.mkdtemp(prefix="tmp", dir=SCENE_CACHE)
    try:
        subprocess.run([program, "--output", staging, *args], check=True,
                       stdout=subprocess.DEVNULL)
        shutil.copytree(staging, output, dirs_exist_ok=True)
        try:
            os.rename(staging, cached)  # another run may have stored it
        except OSError:
            pass
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    _prune_scene_cache()


# ---------------------------------------------------------------------------
# Rigs of the rendered sets (cam_from_world poses for sphera_render --rig)


def rig_line(name, model, width, height, params, centre, yaw_deg,
             pitch_deg=0.0, roll_deg=0.0):
    """A sphera_render rig line. The camera heads `yaw` about the vertical
    (0 = +Z, 90 = +X), then pitches (positive = up, the world's -Y) and
    rolls; centre is in world coordinates (+Y down, floor at y = 1.5)."""
    d = math.pi / 180
    world_from_cam = matmul(matmul(axis_rotation(1, yaw_deg * d),
                                   axis_rotation(0, pitch_deg * d)),
                            axis_rotation(2, roll_deg * d))
    rotation = transpose(world_from_cam)
    t = [-v for v in mat_vec(rotation, centre)]
    q = quaternion_from_matrix(rotation)
    numbers = " ".join("%.12g" % v for v in list(q) + t)
    return "%s %s %d %d %s | %s" % (name, model, width, height,
                                   " ".join("%.12g" % p for p in params),
                                   numbers)


def write_rig(path, lines):
    """Writes rig LINES to PATH, one a line."""
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


FISHEYE_PARAMS = [450.56, 450.56, 512, 512, 1.0, 0, 0, 0, 0]  # 190 deg
EQUIRECT_PARAMS = [2048, 1024]
PINHOLE_800_PARAMS = [400, 400, 400, 300]  # 90 deg horizontal


def fisheye190_rig(model="UNIFIED_OMNI", params=None):
    """12 fisheye cameras: the room9 grid plus 3 off-grid, looking in varied
    directions (horizontal, tilted, straight up and down); 190-degree
    UNIFIED_OMNI lenses unless `model` and `params` say otherwise."""
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
    return [rig_line("fish%02d" % i, model, 1024, 1024,
                     FISHEYE_PARAMS if params is None else params, c, yaw,
                     pitch, roll)
            for i, (c, yaw, pitch, roll) in enumerate(poses)]


# Kannala-Brandt lens, 1024x1024: 160 degrees across the 537 px image circle
# of the renderer's --realistic preset (radius 1.05 half heights).
FISHEYE160_PARAMS = [374.3, 374.3, 512, 512, 0.02, -0.004, 0.0006, -0.00005]


def fisheye160_rig():
    """The 12 poses of fisheye190_rig with OPENCV_FISHEYE lenses under 180
    degrees, which upstream COLMAP knows too."""
    return fisheye190_rig("OPENCV_FISHEYE", FISHEYE160_PARAMS)


# EUCM lens, 1024x1024: 160 degrees across the same 537 px image circle
# (alpha 0.6, beta 1: 80 degrees at 1.472 focal lengths); the frame's edges
# at 512 px lie 76 degrees off the axis.
EUCM160_PARAMS = [364.8, 364.8, 512, 512, 0.6, 1.0]


def eucm160_rig():
    """The 12 poses of fisheye190_rig with EUCM lenses under 180 degrees,
    which upstream COLMAP knows too (its EUCM stops at z > 0)."""
    return fisheye190_rig("EUCM", EUCM160_PARAMS)


# Kannala-Brandt lens with tangential and thin-prism terms, 1024x1024: the
# radial terms of FISHEYE160_PARAMS (k1, k2 at positions 4, 5 and k3, k4 at
# 8, 9 in THIN_PRISM_FISHEYE's order), p1 = p2 = 2e-4, sx1 = sy1 = 1e-4; 160
# degrees (79.9 to 80.1 by direction) across the same 537 px image circle,
# the frame's edges at 512 px 76.3 to 76.5 degrees off the axis, monotone
# (Jacobian determinant above 0.99) out to 100 degrees.
THINPRISM160_PARAMS = [374.3, 374.3, 512, 512, 0.02, -0.004, 2e-4, 2e-4,
                       0.0006, -0.00005, 1e-4, 1e-4]


def thinprism160_rig():
    """The 12 poses of fisheye190_rig with THIN_PRISM_FISHEYE lenses under
    180 degrees, which upstream COLMAP knows too."""
    return fisheye190_rig("THIN_PRISM_FISHEYE", THINPRISM160_PARAMS)


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
