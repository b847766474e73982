"""The scene cache of sphera_common.run_render: a cached scene is the
renderer's output byte for byte, and a changed renderer, argument or file
argument renders afresh instead of reusing another scene."""
import filecmp
import os
import shutil
import stat
import unittest

import sphera_common
from cli_util import TempDirTestCase, main_with_render
from sphera_common import rig_line, run_render, write_rig

ARGS = ("--seed", "3", "--layout", "room9", "--model", "EQUIRECTANGULAR",
        "--width", "96", "--height", "48", "--supersample", "1")


def same_tree(left, right):
    """True when the folders hold the same files with the same bytes."""
    comparison = filecmp.dircmp(left, right)
    if comparison.left_only or comparison.right_only:
        return False
    _, mismatch, errors = filecmp.cmpfiles(left, right, comparison.common_files,
                                           shallow=False)
    return not mismatch and not errors and all(
        same_tree(os.path.join(left, d), os.path.join(right, d))
        for d in comparison.common_dirs)


class SceneCacheTest(TempDirTestCase):
    def setUp(self):
        super().setUp()
        self.saved = sphera_common.SCENE_CACHE
        sphera_common.SCENE_CACHE = self.path("cache")
        # A copy of the renderer that counts its runs: a wrapper script
        # would change the key, so the copy itself is the program.
        self.program = self.path("sphera_render")
        shutil.copy(sphera_common.RENDER, self.program)

    def tearDown(self):
        sphera_common.SCENE_CACHE = self.saved
        super().tearDown()

    def entries(self):
        return sorted(name for name in os.listdir(self.path("cache"))
                      if not name.startswith("tmp"))

    def test_a_cached_scene_is_the_rendered_scene(self):
        run_render(self.path("first"), *ARGS, program=self.program)
        self.assertEqual(len(self.entries()), 1)
        # Without the program the scene can only come from the cache.
        stored = self.entries()[0]
        os.chmod(self.program, stat.S_IRUSR)
        run_render(self.path("second"), *ARGS, program=self.program)
        self.assertEqual(self.entries(), [stored])
        sphera_common.SCENE_CACHE = ""
        run_render(self.path("fresh"), *ARGS, program=sphera_common.RENDER)
        self.assertTrue(same_tree(self.path("fresh"), self.path("second")))
        self.assertTrue(os.path.isdir(self.path("fresh", "images")))

    def test_a_changed_argument_or_rig_file_renders_afresh(self):
        run_render(self.path("a"), *ARGS, program=self.program)
        run_render(self.path("b"), *ARGS[:-1], "2", program=self.program)
        self.assertEqual(len(self.entries()), 2)
        self.assertFalse(same_tree(self.path("a"), self.path("b")))
        rig = self.path("rig.txt")
        params = [30, 30, 32, 32, 1.0, 0, 0, 0, 0]  # a 64-px 190-deg lens
        write_rig(rig, [rig_line("lens", "UNIFIED_OMNI", 64, 64, params,
                                 (0, 0, 0), 0)])
        run_render(self.path("c"), "--seed", "3", "--rig", rig,
                   program=self.program)
        write_rig(rig, [rig_line("lens", "UNIFIED_OMNI", 64, 64, params,
                                 (0, 0, 0), 90)])
        run_render(self.path("d"), "--seed", "3", "--rig", rig,
                   program=self.program)
        self.assertEqual(len(self.entries()), 4)
        self.assertFalse(same_tree(self.path("c"), self.path("d")))

    def test_a_changed_renderer_renders_afresh(self):
        run_render(self.path("a"), *ARGS, program=self.program)
        with open(self.program, "ab") as f:
            f.write(b"\0")  # trailing bytes: the ELF program still runs
        run_render(self.path("b"), *ARGS, program=self.program)
        self.assertEqual(len(self.entries()), 2)

    def test_a_failed_render_leaves_nothing_in_the_cache(self):
        with self.assertRaises(Exception):
            run_render(self.path("bad"), "--layout", "no_such_layout",
                       program=self.program)
        self.assertEqual(self.entries(), [])


if __name__ == "__main__":
    main_with_render()
