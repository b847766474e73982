"""The COLMAP 4.x source tarball is checked before anything is unpacked: a
damaged or missing tarball stops the configuration with a message that names
the file and the pinned SHA-256, and leaves no prepared source tree and no
build files behind."""
import os
import subprocess
import tempfile
import unittest

from cli_util import TempDirTestCase
from sphera_common import REPO_ROOT

COLMAP_SHA256 = \
    "1c6c1a735774d8bc442900d52aac5359dcc9c7ffe53d3daba054fa3095de8dc1"


class ColmapSourceTest(TempDirTestCase):
    def configure(self, tarball):
        build_dir = self.path("build")
        result = subprocess.run(
            ["cmake", "-S", REPO_ROOT, "-B", build_dir, "-G", "Ninja",
             "-DSPHERA_COLMAP4_TARBALL=" + tarball],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
            timeout=600)
        return result, build_dir

    def check_refused(self, tarball):
        result, build_dir = self.configure(tarball)
        message = " ".join(result.stdout.split())
        self.assertNotEqual(result.returncode, 0, message)
        self.assertIn(tarball, message)
        self.assertIn(COLMAP_SHA256, message)
        for leftover in ("build.ninja", "colmap-src", "colmap-stage",
                         "colmap4-deps"):
            self.assertFalse(os.path.exists(os.path.join(build_dir, leftover)),
                             leftover)
        return message

    def test_damaged_tarball_is_named_with_its_checksum(self):
        tarball = self.path("colmap-5d968cf.tar.gz")
        with open(tarball, "wb") as f:
            f.write(os.urandom(4096))
        message = self.check_refused(tarball)
        self.assertIn("damaged", message)

    def test_missing_tarball_is_named_with_its_checksum(self):
        message = self.check_refused(self.path("nowhere", "colmap.tar.gz"))
        self.assertIn("not found", message)


if __name__ == "__main__":
    unittest.main()
