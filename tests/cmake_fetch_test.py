"""Without tarballs the configuration fetches COLMAP by git at its full commit
and PoseLib and faiss as archives checked against their SHA-256
(cmake/ColmapSource.cmake). Local mirrors stand in for the public hosts: a
bare git repository made from the COLMAP tarball's tree (its commit id is its
own, passed with SPHERA_COLMAP_GIT_COMMIT) and file:// URLs of the PoseLib and
faiss tarballs (their sums passed with SPHERA_*_URL_SHA256). Configure only;
nothing is built. Skipped when ../shared/peers is absent."""
import glob
import os
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile
import unittest

from cli_util import SKIP_EXIT_CODE, TempDirTestCase
from sphera_common import REPO_ROOT

PEERS_DIR = os.path.abspath(os.path.join(REPO_ROOT, "..", "shared", "peers"))
COLMAP_TARBALL = os.path.join(PEERS_DIR, "colmap-5d968cf.tar.gz")
POSELIB_TARBALL = os.path.join(PEERS_DIR, "PoseLib-a69263d.tar.gz")
FAISS_TARBALL = os.path.join(PEERS_DIR, "faiss-1.14.1.tar.gz")
UPSTREAM_COMMIT = "5d968cf38aa2574fd284b0dc86c3d58d124940b3"
# Upstream's URL_HASH of PoseLib fa7280f (src/thirdparty/CMakeLists.txt).
UPSTREAM_POSELIB_SHA256 = \
    "5408d4ae8ce367cb2f076bc6c5f0f6f78abd3573d2c015304b04e46f23455f5b"
POSELIB_TARBALL_SHA256 = \
    "7b8d9b0aae73feeb7ba202261e1ff90dd7d166316b263210b6f9456303722e2d"
FAISS_TARBALL_SHA256 = \
    "0216d38d8c5c460433815b72d3cde6725eaa5d5770576277a2abc01ffc414d20"


def git(cwd, *args):
    return subprocess.run(
        ["git", "-c", "user.name=sphera", "-c", "user.email=sphera@localhost",
         *args], cwd=cwd, check=True, stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT, text=True).stdout.strip()


def one_line(text):
    return " ".join(text.split())


class ColmapFetchTest(TempDirTestCase):
    @classmethod
    def setUpClass(cls):
        # The mirror of COLMAP's repository: the tarball's tree as one commit.
        cls.mirror_root = tempfile.mkdtemp(prefix="sphera_mirror_")
        with tarfile.open(COLMAP_TARBALL) as tar:
            tar.extractall(cls.mirror_root)
        tree = os.path.join(cls.mirror_root, "colmap-5d968cf")
        git(tree, "init", "--quiet")
        git(tree, "add", "--force", "--all")
        git(tree, "commit", "--quiet", "-m", "COLMAP 5d968cf")
        cls.commit = git(tree, "rev-parse", "HEAD")
        cls.bare = os.path.join(cls.mirror_root, "colmap.git")
        git(cls.mirror_root, "clone", "--quiet", "--bare", tree, cls.bare)
        shutil.rmtree(tree)
        cls.git_url = "file://" + cls.bare

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.mirror_root, ignore_errors=True)

    def mirror_args(self, **overrides):
        """The cache variables of a configuration from the local mirrors:
        no tarball anywhere, a cache of its own."""
        values = {
            "SPHERA_PEERS_DIR": "",
            "SPHERA_CACHE_DIR": self.path("cache"),
            "SPHERA_COLMAP_GIT_URL": self.git_url,
            "SPHERA_COLMAP_GIT_COMMIT": self.commit,
            "SPHERA_POSELIB_URL": "file://" + POSELIB_TARBALL,
            "SPHERA_POSELIB_URL_SHA256": POSELIB_TARBALL_SHA256,
            "SPHERA_FAISS_URL": "file://" + FAISS_TARBALL,
            "SPHERA_FAISS_URL_SHA256": FAISS_TARBALL_SHA256,
        }
        values.update(overrides)
        return ["-D%s=%s" % item for item in values.items()]

    def configure(self, build_name, args):
        build_dir = self.path(build_name)
        result = subprocess.run(
            ["cmake", "-S", REPO_ROOT, "-B", build_dir, "-G", "Ninja", *args],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
            timeout=600)
        return result, build_dir

    def partial_files(self):
        return glob.glob(self.path("**", "*.partial"), recursive=True)

    def assert_nothing_prepared(self, build_dir):
        for leftover in ("build.ninja", "colmap-src", "colmap-stage",
                         "colmap4-deps"):
            self.assertFalse(os.path.exists(os.path.join(build_dir, leftover)),
                             leftover)
        self.assertEqual(self.partial_files(), [])

    def test_sources_come_from_the_mirrors_and_are_kept(self):
        # Leftovers of an interrupted earlier run are replaced, not used.
        cache = self.path("cache")
        os.makedirs(os.path.join(cache, "downloads"))
        os.makedirs(os.path.join(cache, "colmap-%s.partial" % self.commit,
                                 "src"))
        with open(os.path.join(cache, "downloads",
                               "PoseLib-PoseLib-a69263d.tar.gz.partial"),
                  "wb") as f:
            f.write(b"half a download")

        result, build_dir = self.configure("build", self.mirror_args())
        self.assertEqual(result.returncode, 0, result.stdout)
        self.assertIn("Fetching COLMAP commit " + self.commit, result.stdout)
        self.assertIn("Fetching PoseLib from file://", result.stdout)
        self.assertIn("Fetching faiss from file://", result.stdout)
        with open(os.path.join(build_dir, "colmap-src.stamp")) as f:
            self.assertIn("source=git " + self.commit, f.read())
        # The patch series went onto the fetched tree (patch 0004 puts
        # SPHERA's commands into colmap's command table).
        with open(os.path.join(build_dir, "colmap-src", "src", "colmap", "exe",
                               "colmap.cc")) as f:
            self.assertIn('#include "colmap_ext/exe/sphera_commands.h"',
                          f.read())
        self.assertEqual(git(os.path.join(cache, "colmap-" + self.commit),
                             "rev-parse", "HEAD"), self.commit)
        self.assertEqual(sorted(os.listdir(os.path.join(cache, "downloads"))),
                         ["PoseLib-PoseLib-a69263d.tar.gz",
                          "faiss-faiss-1.14.1.tar.gz"])
        self.assertEqual(self.partial_files(), [])

        # A second build tree finds everything in the cache: mirrors gone.
        gone = "file://" + self.path("gone")
        result, _ = self.configure("build2", self.mirror_args(
            SPHERA_COLMAP_GIT_URL=gone + "/colmap.git",
            SPHERA_POSELIB_URL=gone + "/PoseLib-a69263d.tar.gz",
            SPHERA_FAISS_URL=gone + "/faiss-1.14.1.tar.gz"))
        self.assertEqual(result.returncode, 0, result.stdout)
        self.assertNotIn("Fetching", result.stdout)

    def test_wrong_commit_is_refused_with_its_id(self):
        # The mirror lacks upstream's commit: the pinned id is refused.
        result, build_dir = self.configure("build", self.mirror_args(
            SPHERA_COLMAP_GIT_COMMIT=UPSTREAM_COMMIT))
        message = one_line(result.stdout)
        self.assertNotEqual(result.returncode, 0, message)
        self.assertIn("fetch: commit %s of %s" % (UPSTREAM_COMMIT, self.git_url),
                      message)
        self.assertIn("-DSPHERA_COLMAP_GIT_URL=", message)
        self.assertNotIn("PoseLib tarball", message)
        self.assert_nothing_prepared(build_dir)
        self.assertFalse(glob.glob(self.path("cache", "colmap-*")))

        # An abbreviated id does not authenticate a source.
        result, build_dir = self.configure("build", self.mirror_args(
            SPHERA_COLMAP_GIT_COMMIT=self.commit[:12]))
        message = one_line(result.stdout)
        self.assertNotEqual(result.returncode, 0, message)
        self.assertIn("SPHERA_COLMAP_GIT_COMMIT='%s' is not a full 40-digit "
                      "commit id" % self.commit[:12], message)
        self.assert_nothing_prepared(build_dir)

    def test_wrong_checksum_stops_and_the_next_run_retries(self):
        # The snapshot tarball is not upstream's PoseLib archive: upstream's
        # sum, the default, refuses it.
        result, build_dir = self.configure("build", self.mirror_args(
            SPHERA_POSELIB_URL_SHA256=UPSTREAM_POSELIB_SHA256))
        message = one_line(result.stdout)
        self.assertNotEqual(result.returncode, 0, message)
        self.assertIn("failed: the download has SHA-256 %s, expected %s" %
                      (POSELIB_TARBALL_SHA256, UPSTREAM_POSELIB_SHA256),
                      message)
        self.assertIn("-DSPHERA_POSELIB_URL_SHA256=", message)
        self.assertNotIn("faiss tarball", message)
        self.assert_nothing_prepared(build_dir)
        self.assertFalse(glob.glob(self.path("cache", "downloads", "PoseLib*")))

        result, build_dir = self.configure("build", self.mirror_args())
        self.assertEqual(result.returncode, 0, result.stdout)
        self.assertTrue(os.path.exists(os.path.join(build_dir, "build.ninja")))
        # Unpacked where a build from the tarball unpacks it (one path for
        # ccache), its stamp naming the archive it came from.
        deps = os.path.join(build_dir, "colmap4-deps")
        self.assertTrue(os.path.exists(
            os.path.join(deps, "PoseLib", "CMakeLists.txt")))
        with open(os.path.join(deps, "PoseLib.stamp")) as stamp:
            self.assertIn(POSELIB_TARBALL_SHA256.lower(), stamp.read())

    def test_no_source_names_each_one_once(self):
        gone = "file://" + self.path("gone")
        args = self.mirror_args(
            SPHERA_COLMAP_GIT_URL=gone + "/colmap.git",
            SPHERA_POSELIB_URL=gone + "/poselib.zip",
            SPHERA_FAISS_URL=gone + "/faiss.zip")
        result, build_dir = self.configure("build", args)
        message = one_line(result.stdout)
        self.assertNotEqual(result.returncode, 0, message)
        self.assertEqual(message.count("CMake Error"), 1, message)
        cache = self.path("cache")
        for name, url, variable in (
                ("colmap-5d968cf", gone + "/colmap.git", "SPHERA_COLMAP_GIT_URL"),
                ("PoseLib-a69263d", gone + "/poselib.zip", "SPHERA_POSELIB_URL"),
                ("faiss-1.14.1", gone + "/faiss.zip", "SPHERA_FAISS_URL")):
            self.assertIn("tarball %s.tar.gz not in: %s/%s.tar.gz" %
                          (name, cache, name), message)
            self.assertIn(url, message)
            self.assertIn("-D%s=<mirror>" % variable, message)
        self.assert_nothing_prepared(build_dir)

    def test_pins_are_those_of_the_colmap_commit(self):
        script = self.path("print_pins.cmake")
        with open(script, "w") as f:
            f.write("include(%s/cmake/ColmapPins.cmake)\n" % REPO_ROOT)
            for name in ("COLMAP_PINNED_COMMIT", "POSELIB_PINNED_URL",
                         "POSELIB_PINNED_SHA256", "FAISS_PINNED_URL",
                         "FAISS_PINNED_SHA256"):
                f.write('message("%s=${SPHERA_%s}")\n' % (name, name))
        output = subprocess.run(["cmake", "-P", script], check=True,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                text=True).stdout
        pins = dict(line.split("=", 1) for line in output.splitlines())
        with tarfile.open(COLMAP_TARBALL) as tar:
            # git archive records the commit in the tarball's pax header.
            self.assertEqual(pins["COLMAP_PINNED_COMMIT"],
                             tar.pax_headers["comment"])
            thirdparty = tar.extractfile(
                "colmap-5d968cf/src/thirdparty/CMakeLists.txt").read().decode()
        for dep, key in (("poselib", "POSELIB"), ("faiss", "FAISS")):
            declared = re.search(
                r"FetchContent_Declare\(%s\s+URL (\S+)\s+URL_HASH SHA256=(\w+)"
                % dep, thirdparty)
            self.assertIsNotNone(declared, dep)
            self.assertEqual(pins[key + "_PINNED_URL"], declared.group(1))
            self.assertEqual(pins[key + "_PINNED_SHA256"], declared.group(2))


if __name__ == "__main__":
    missing = [path for path in (COLMAP_TARBALL, POSELIB_TARBALL, FAISS_TARBALL)
               if not os.path.exists(path)]
    if missing:
        print("SKIP: needs %s (the source tarballs beside the repository) to "
              "make local mirrors; not available here" % ", ".join(missing))
        sys.exit(SKIP_EXIT_CODE)
    unittest.main()
