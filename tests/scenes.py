"""Rendered scenes that several tests share, each made once per test run:
the renderer's images and ground truth, and a database of their features
extracted and matched exhaustively (COLMAP's defaults, on the CPU).

Under ctest every test gets SPHERA_SCENE_DIR (a folder of the build tree),
and a setup test per scene (`scene.NAME`, a ctest fixture; run as
`scenes.py NAME...`) makes it afresh before the tests that require it: a
scene is never left over from an earlier run, whose renderer or colmap may
have differed. A test run outside ctest makes the scenes it needs in a
temporary folder of its own, removed when it exits.

A test reads a scene and copies its database before running a command
that may write to it (mapper, rig_configurator)."""
import atexit
import fcntl
import os
import shutil
import sys
import tempfile

from cli_util import require_render
from sphera_common import (extract_features, fisheye190_rig,
                           match_exhaustive, read_text_cameras, run_render,
                           write_rig)


def _room9_equirect(scene):
    """The SPHERA paper's room seen by 9 equirectangular cameras of
    2048 x 1024 pixels (3 x 3 rays a pixel): sfm_rendered_test's
    incremental mapper, sphere_models_test's global mapper."""
    run_render(scene, "--seed", "7", "--layout", "room9", "--model",
               "EQUIRECTANGULAR", "--width", "2048", "--height", "1024",
               "--supersample", "3")
    return "EQUIRECTANGULAR"


def _fisheye190(scene):
    """12 UNIFIED_OMNI lenses of 190 degrees in the room (the SfM
    benchmark's room_fisheye190 set, 2 x 2 rays a pixel):
    sphere_models_test's incremental and global mappers."""
    rig = scene + "_rig.txt"
    write_rig(rig, fisheye190_rig())
    run_render(scene, "--seed", "7", "--rig", rig, "--supersample", "2")
    return "UNIFIED_OMNI"


# name: the function that renders the scene into a folder and returns the
# camera model its features are extracted as (one camera, the ground
# truth's parameters).
RECIPES = {
    "room9_equirect": _room9_equirect,
    "fisheye190": _fisheye190,
}


class Scene:
    """A made scene: its folder `root`, the renderer's output `path`
    (images/, sparse_gt/, depth/), `images`, `sparse_gt`, the extracted
    and matched `database`, and the `model` and `params` of its camera."""

    def __init__(self, root):
        self.root = root
        self.path = os.path.join(root, "scene")
        self.images = os.path.join(self.path, "images")
        self.sparse_gt = os.path.join(self.path, "sparse_gt")
        self.database = os.path.join(root, "database.db")
        cameras = read_text_cameras(self.sparse_gt)
        self.model, _, _, self.params = next(iter(cameras.values()))

    def copy_database(self, path):
        """PATH, a copy of the scene's database."""
        shutil.copy(self.database, path)
        return path


def _make(name, folder):
    """Makes scene NAME in FOLDER (replacing what is there): rendered into
    FOLDER.tmp, extracted and matched, then renamed, so that a scene folder
    is complete or absent."""
    tmp = folder + ".tmp"
    shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp)
    scene = os.path.join(tmp, "scene")
    model = RECIPES[name](scene)
    params = next(iter(read_text_cameras(
        os.path.join(scene, "sparse_gt")).values()))[3]
    database = os.path.join(tmp, "database.db")
    extract_features(database, os.path.join(scene, "images"), model,
                     params=params)
    match_exhaustive(database)
    shutil.rmtree(folder, ignore_errors=True)
    os.rename(tmp, folder)


_private_root = None


def _root():
    """The folder of the shared scenes: SPHERA_SCENE_DIR, or a temporary
    folder of this process."""
    global _private_root
    root = os.environ.get("SPHERA_SCENE_DIR")
    if root:
        os.makedirs(root, exist_ok=True)
        return root
    if _private_root is None:
        _private_root = tempfile.mkdtemp(prefix="sphera_scenes_")
        atexit.register(shutil.rmtree, _private_root, True)
    return _private_root


def shared_scene(name, remake=False):
    """The Scene NAME, made first when it is missing (or with REMAKE).
    A lock lets concurrent tests make it once."""
    if name not in RECIPES:
        raise KeyError(f"no shared scene {name!r} (scenes: "
                       f"{', '.join(sorted(RECIPES))})")
    root = _root()
    folder = os.path.join(root, name)
    with open(os.path.join(root, name + ".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if remake or not os.path.isdir(folder):
            _make(name, folder)
    return Scene(folder)


if __name__ == "__main__":
    # The ctest fixture's setup: the named scenes, made afresh.
    if len(sys.argv) < 2:
        raise SystemExit(f"usage: scenes.py NAME... ({', '.join(RECIPES)})")
    require_render()
    for scene_name in sys.argv[1:]:
        made = shared_scene(scene_name, remake=True)
        print(f"{scene_name}: {made.root}")
