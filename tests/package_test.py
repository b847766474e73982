"""SPHERA installs as a program: `cpack -G DEB` in the build tree makes a
package that conflicts with, provides and replaces Debian's colmap and whose
Depends are the packages of the shared libraries its programs link; unpacked
into a temporary root (dpkg-deb -x), its colmap lists SPHERA's commands, all
its libraries resolve, and its sphera_demo reconstructs a scene rendered by
its sphera_render. `cmake --install` into a prefix that cannot be written
fails with a message that says what to do. The build tree is the one of
SPHERA_COLMAP (BUILD/bin/colmap)."""
import glob
import os
import re
import shutil
import subprocess
import unittest

from cli_util import TempDirTestCase
from sphera_common import COLMAP

BUILD_DIR = os.path.dirname(os.path.dirname(os.path.abspath(COLMAP)))
SPHERA_COMMANDS = ("dual_fisheye_splitter", "model_evaluator",
                   "rig_calibration", "sphere_bundle_adjuster",
                   "sphere_undistorter", "strecha_importer")


def run(*args, **kwargs):
    return subprocess.run(args, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, **kwargs)


def needed_libraries(program):
    """The sonames a program links directly (its ELF NEEDED entries)."""
    dynamic = run("objdump", "-p", program, check=True).stdout
    return re.findall(r"^\s*NEEDED\s+(\S+)", dynamic, re.MULTILINE)


def resolved_libraries(program):
    """{soname: path} of every shared library ldd resolves for a program;
    sonames it cannot find map to None."""
    libraries = {}
    for line in run("ldd", program, check=True).stdout.splitlines():
        match = re.match(r"\s*(\S+) => (not found|(\S+) \(0x)", line)
        if match:
            libraries[match.group(1)] = match.group(3)
        # The dynamic loader is listed by its path alone.
        match = re.match(r"\s*(/\S+) \(0x", line)
        if match:
            libraries[os.path.basename(match.group(1))] = match.group(1)
    return libraries


def owning_package(path):
    """The Debian package that installed the library at path (through
    symbolic links and alternatives, and either side of the merged /usr)."""
    real = os.path.realpath(path)
    candidates = [path, real]
    for candidate in list(candidates):
        if candidate.startswith("/usr/"):
            candidates.append(candidate[len("/usr"):])
        else:
            candidates.append("/usr" + candidate)
    for candidate in candidates:
        result = run("dpkg", "-S", candidate)
        if result.returncode == 0:
            # "libfoo1:amd64: /usr/lib/..." -> "libfoo1"
            return result.stdout.splitlines()[0].split(":")[0].strip()
    return None


def names_of(package):
    """The package's name and the virtual packages it provides (a library
    behind alternatives, such as liblapack.so.3 of libatlas3-base)."""
    provides = run("dpkg-query", "-W", "-f", "${Provides}", package,
                   check=True).stdout
    return {package} | {re.sub(r"\s*\(.*\)", "", name).strip()
                        for name in provides.split(",") if name.strip()}


def depends_groups(depends):
    """Depends "a (>= 1), b | c" -> [{"a"}, {"b", "c"}]."""
    groups = []
    for group in depends.split(","):
        names = {re.sub(r"\s*\(.*\)", "", alternative).strip()
                 for alternative in group.split("|")}
        groups.append({name.split(":")[0] for name in names if name})
    return groups


class PackageTest(TempDirTestCase):
    @classmethod
    def setUpClass(cls):
        cls.shared = os.path.join(
            os.environ.get("TMPDIR", "/tmp"), "sphera_package_test_%d" % os.getpid())
        shutil.rmtree(cls.shared, ignore_errors=True)
        os.makedirs(cls.shared)
        result = run("cpack", "-G", "DEB", "--config",
                     os.path.join(BUILD_DIR, "CPackConfig.cmake"),
                     "-B", os.path.join(cls.shared, "package"),
                     cwd=BUILD_DIR, timeout=1200)
        if result.returncode != 0:
            raise AssertionError("cpack failed:\n" + result.stdout)
        packages = glob.glob(os.path.join(cls.shared, "package", "*.deb"))
        if len(packages) != 1:
            raise AssertionError("cpack made %s:\n%s" % (packages, result.stdout))
        cls.deb = packages[0]
        cls.root = os.path.join(cls.shared, "root")
        run("dpkg-deb", "-x", cls.deb, cls.root, check=True)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.shared, ignore_errors=True)

    def field(self, name):
        return run("dpkg-deb", "-f", self.deb, name, check=True).stdout.strip()

    def program(self, name):
        return os.path.join(self.root, "usr", "bin", name)

    def test_package_takes_the_place_of_debian_colmap(self):
        self.assertEqual(self.field("Package"), "sphera")
        for field in ("Conflicts", "Provides", "Replaces"):
            self.assertEqual(self.field(field), "colmap", field)
        contents = run("dpkg-deb", "-c", self.deb, check=True).stdout
        for path in ("./usr/bin/colmap", "./usr/bin/sphera_render",
                     "./usr/bin/sphera_demo",
                     "./usr/share/doc/sphera/README.md"):
            self.assertIn(path, contents)
        # Only programs: no headers, static libraries or CMake files.
        self.assertNotIn("/include/", contents)
        self.assertNotIn(".a\n", contents)

    def test_depends_are_the_packages_of_the_linked_libraries(self):
        groups = depends_groups(self.field("Depends"))
        linked = set()
        for name in ("colmap", "sphera_render"):
            program = self.program(name)
            resolved = resolved_libraries(program)
            missing = [soname for soname, path in resolved.items() if not path]
            self.assertEqual(missing, [], name + ": libraries not found")
            for soname in needed_libraries(program):
                self.assertIn(soname, resolved.keys(), name)
                package = owning_package(resolved[soname])
                self.assertIsNotNone(package, resolved[soname])
                names = names_of(package)
                linked |= names
                self.assertTrue(any(names & group for group in groups),
                                "%s (%s of %s) is not in Depends %s"
                                % (package, soname, name, groups))
        # Every dependency but sqlite3 (the demo's counts) is a linked
        # library's package.
        for group in groups:
            if group == {"sqlite3"}:
                continue
            self.assertTrue(group & linked,
                            "Depends %s: no linked library of it" % group)
        self.assertIn({"sqlite3"}, groups)

    def test_programs_carry_no_rpath(self):
        # Every library of the build is static: the system's libraries are
        # found by the loader's default paths, never through an RPATH.
        for name in ("colmap", "sphera_render"):
            dynamic = run("objdump", "-p", self.program(name), check=True).stdout
            self.assertNotRegex(dynamic, r"(?m)^\s*(RPATH|RUNPATH)\s", name)

    def test_unpacked_colmap_lists_sphera_commands(self):
        result = run(self.program("colmap"), "help", timeout=60)
        self.assertEqual(result.returncode, 0, result.stdout)
        for command in SPHERA_COMMANDS + ("feature_extractor", "mapper"):
            self.assertRegex(result.stdout, r"(?m)^\s*%s\s*$" % command)

    def test_unpacked_demo_reconstructs_a_rendered_scene(self):
        scene = self.path("scene")
        run(self.program("sphera_render"), "--output", scene, "--layout",
            "room9", "--model", "EQUIRECTANGULAR", "--width", "768",
            "--height", "384", "--supersample", "1", "--seed", "1",
            check=True, timeout=600)
        env = {key: value for key, value in os.environ.items()
               if key not in ("SPHERA_COLMAP", "SPHERA_RENDER")}
        env["PATH"] = "/usr/bin:/bin"
        result = run(self.program("sphera_demo"), os.path.join(scene, "images"),
                     cwd=self.tmp, env=env, timeout=900)
        self.assertEqual(result.returncode, 0, result.stdout)
        work_dir = os.path.join(self.tmp, "sphera_demo")
        self.assertIn("log: " + os.path.join(work_dir, "demo.log"),
                      result.stdout)
        with open(os.path.join(work_dir, "demo.log")) as f:
            log = f.read()
        # The installed demo ran the unpacked colmap, not the build's.
        self.assertIn("=== feature extraction: %s feature_extractor"
                      % self.program("colmap"), log)
        registered = re.search(r"(?m)^0: Registered images: (\d+)$",
                               result.stdout)
        self.assertIsNotNone(registered, result.stdout)
        self.assertGreaterEqual(int(registered.group(1)), 8, result.stdout)
        self.assertIn("registered: %s/9" % registered.group(1), result.stdout)

    def test_install_into_an_unwritable_prefix_says_what_to_do(self):
        # Under a regular file no folder can be made, not even by root.
        blocker = self.path("a_file")
        with open(blocker, "w") as f:
            f.write("not a folder\n")
        prefix = os.path.join(blocker, "prefix")
        result = run("cmake", "--install", BUILD_DIR, "--prefix", prefix,
                     timeout=600)
        message = " ".join(result.stdout.split())
        self.assertNotEqual(result.returncode, 0, message)
        self.assertIn("SPHERA cannot be installed into %s: %s/bin is not a "
                      "folder this user can write" % (prefix, prefix), message)
        self.assertIn("--prefix ~/.local", message)

    def test_install_into_a_prefix(self):
        prefix = self.path("prefix")
        result = run("cmake", "--install", BUILD_DIR, "--prefix", prefix,
                     timeout=600)
        self.assertEqual(result.returncode, 0, result.stdout)
        self.assertEqual(sorted(os.listdir(os.path.join(prefix, "bin"))),
                         ["colmap", "sphera_demo", "sphera_render"])
        result = run(os.path.join(prefix, "bin", "colmap"), "help", timeout=60)
        self.assertEqual(result.returncode, 0, result.stdout)
        self.assertIn("sphere_bundle_adjuster", result.stdout)


if __name__ == "__main__":
    if not os.path.exists(COLMAP):
        raise SystemExit("SPHERA_COLMAP=%r is not the built colmap" % COLMAP)
    unittest.main()
