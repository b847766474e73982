"""`colmap sphere_undistorter`: a reconstruction of panoramas and a
perspective image becomes a COLMAP dense workspace (or a splatting layout) of
PINHOLE views; bad input fails with a message and leaves nothing behind."""
import math
import os
import random
import struct
import zlib

import sphera_common
from cli_util import TempDirTestCase, listing
from sphera_common import mat_vec, model_to_text, rotation_matrix, run_colmap

import unittest


def write_png(path, width, height, pixel):
    """Writes an 8-bit grayscale PNG; pixel(x, y) -> 0..255."""
    rows = bytearray()
    for y in range(height):
        rows.append(0)  # filter: none
        rows.extend(pixel(x, y) for x in range(width))

    def chunk(kind, data):
        body = kind + data
        return (struct.pack(">I", len(data)) + body +
                struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0,
                                           0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(bytes(rows))))
        f.write(chunk(b"IEND", b""))


def texture(x, y):
    return int(128 + 60 * math.sin(x * 0.11) * math.cos(y * 0.07) +
               40 * math.sin((x + 2 * y) * 0.031)) & 0xFF


def equirect_pixel(ray, width, height):
    x, y, z = ray
    theta = math.atan2(x, z)
    phi = math.atan2(-y, math.hypot(x, z))
    return ((theta / (2 * math.pi) + 0.5) * width,
            (0.5 - phi / math.pi) * height)


PANO_W, PANO_H = 512, 256
# cam_from_world rotations (w, x, y, z) and translations of two panoramas.
POSES = [((1.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
         ((math.cos(0.3), 0.0, math.sin(0.3), 0.0), (0.4, 0.0, -0.2))]


def write_scene(root, num_points=60, seed=4):
    """Sparse model (text) and images: 2 panoramas, 1 perspective image in a
    sub-folder. Returns (sparse_path, image_path, num_points)."""
    rng = random.Random(seed)
    sparse = os.path.join(root, "sparse_in")
    images = os.path.join(root, "images_in")
    os.makedirs(sparse)
    os.makedirs(os.path.join(images, "persp"))
    points = []
    for _ in range(num_points):
        d = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(c * c for c in d))
        depth = rng.uniform(2, 6)
        points.append([c / n * depth for c in d])
    tracks = {i + 1: [] for i in range(num_points)}
    image_lines = []
    for image_id, (q, t) in enumerate(POSES, start=1):
        points2d = []
        for j, p in enumerate(points):
            xc = [a + b for a, b in zip(mat_vec(rotation_matrix(*q), p), t)]
            u, v = equirect_pixel(xc, PANO_W, PANO_H)
            tracks[j + 1].append((image_id, len(points2d)))
            points2d.append(f"{u!r} {v!r} {j + 1}")
        image_lines.append(f"{image_id} {' '.join(map(repr, q))} "
                           f"{' '.join(map(repr, t))} 1 pano{image_id}.png")
        image_lines.append(" ".join(points2d))
        write_png(os.path.join(images, f"pano{image_id}.png"), PANO_W,
                  PANO_H, texture)
    # A perspective image (SIMPLE_RADIAL) without observations.
    image_lines.append("3 1 0 0 0 0 0 0.5 2 persp/cam.png")
    image_lines.append("")
    write_png(os.path.join(images, "persp", "cam.png"), 160, 120, texture)
    with open(os.path.join(sparse, "cameras.txt"), "w") as f:
        f.write(f"1 EQUIRECTANGULAR {PANO_W} {PANO_H} {PANO_W} {PANO_H}\n")
        f.write("2 SIMPLE_RADIAL 160 120 150 80 60 -0.05\n")
    with open(os.path.join(sparse, "images.txt"), "w") as f:
        f.write("\n".join(image_lines) + "\n")
    with open(os.path.join(sparse, "points3D.txt"), "w") as f:
        for j, p in enumerate(points):
            track = " ".join(f"{i} {k}" for i, k in tracks[j + 1])
            f.write(f"{j + 1} {' '.join(map(repr, p))} 200 200 200 0.5 "
                    f"{track}\n")
    return sparse, images, num_points


def read_text_model(path):
    """cameras, images {name: (camera_id, [(x, y, point3D_id)])}, points
    {id: track length} of a text model."""
    cameras, images, points = sphera_common.read_text_model(path)
    return (cameras,
            {fields[9]: (int(fields[8]), observations)
             for fields, observations in images.values()},
            {point_id: len(track) for point_id, (_, track) in points.items()})


FACES = ["front", "right", "back", "left", "up", "down"]


class SphereUndistorterTest(TempDirTestCase):
    def setUp(self):
        super().setUp()
        self.sparse, self.images, self.num_points = write_scene(self.tmp)

    def export(self, output, *extra, check=True):
        return run_colmap("sphere_undistorter", "--input_path", self.sparse,
                          "--image_path", self.images, "--output_path",
                          output, *extra, check=check)

    def to_text(self, sparse):
        return read_text_model(model_to_text(
            sparse, self.path("text_" + str(len(os.listdir(self.tmp))))))

    def assert_nothing_left(self, output):
        self.assertFalse(os.path.exists(output), output)
        leftovers = [n for n in os.listdir(os.path.dirname(output))
                     if ".tmp-" in n]
        self.assertEqual(leftovers, [])

    def test_colmap_workspace(self):
        output = self.path("workspace")
        result = self.export(output)
        self.assertIn("3 images in, 13 views written", result.stdout)
        self.assertIn("pano1.png -> 6 faces", result.stdout)
        self.assertIn("bytes written", result.stdout)

        names = sorted(f"pano{i}_{face}.jpg" for i in (1, 2) for face in FACES)
        images = sorted(os.path.relpath(os.path.join(d, f),
                                        os.path.join(output, "images"))
                        for d, _, files in os.walk(os.path.join(output,
                                                                "images"))
                        for f in files)
        self.assertEqual(images, sorted(names + ["persp/cam.png"]))
        for name in ("cameras.bin", "images.bin", "points3D.bin"):
            self.assertTrue(os.path.isfile(os.path.join(output, "sparse",
                                                        name)))
        for sub in ("depth_maps", "normal_maps", "consistency_graphs"):
            self.assertTrue(os.path.isdir(os.path.join(output, "stereo", sub,
                                                       "persp")))
        with open(os.path.join(output, "stereo", "patch-match.cfg")) as f:
            lines = f.read().splitlines()
        self.assertEqual(len(lines), 26)
        self.assertEqual(lines[1::2], ["__auto__, 20"] * 13)
        self.assertEqual(sorted(lines[0::2]), sorted(names + ["persp/cam.png"]))
        with open(os.path.join(output, "stereo", "fusion.cfg")) as f:
            self.assertEqual(sorted(f.read().splitlines()),
                             sorted(names + ["persp/cam.png"]))

        cameras, model_images, points = self.to_text(
            os.path.join(output, "sparse"))
        self.assertEqual({c[0] for c in cameras.values()}, {"PINHOLE"})
        face_cameras = [c for c in cameras.values() if c[1] == 128]
        self.assertEqual(len(face_cameras), 1)
        self.assertAlmostEqual(face_cameras[0][3][0], 64.0)
        self.assertEqual(len(model_images), 13)
        # Every point is seen by both panoramas; each panorama observation
        # lands in exactly one face (no overlap), inside it.
        self.assertEqual(len(points), self.num_points)
        self.assertEqual(sum(points.values()), 2 * self.num_points)
        for name, (camera_id, observations) in model_images.items():
            size = cameras[camera_id][1]
            for x, y, point3d_id in observations:
                self.assertTrue(0 <= x < size and 0 <= y < size, name)
                self.assertIn(point3d_id, points)

        # An existing workspace is refused and left untouched.
        before = listing(output)
        result = self.export(output, check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("already holds a workspace", result.stdout)
        self.assertEqual(listing(output), before)

    def test_splatting_layout(self):
        output = self.path("splat")
        self.export(output, "--splatting", "1", "--faces",
                    "front,right,back,left,up", "--face_size", "100",
                    "--overlap_deg", "10")
        self.assertEqual(sorted(os.listdir(output)), ["images", "sparse"])
        self.assertEqual(os.listdir(os.path.join(output, "sparse")), ["0"])
        files = sorted(os.listdir(os.path.join(output, "images")))
        expected = sorted([f"pano{i}_{face}.jpg" for i in (1, 2)
                           for face in FACES[:5]] + ["persp_cam.png"])
        self.assertEqual(files, expected)
        cameras, model_images, points = self.to_text(
            os.path.join(output, "sparse", "0"))
        self.assertEqual({c[0] for c in cameras.values()}, {"PINHOLE"})
        self.assertEqual(sorted(model_images), expected)
        focal = 50 / math.tan(math.radians(50))
        self.assertTrue(any(abs(c[3][0] - focal) < 1e-6
                            for c in cameras.values()))
        # With overlap some observations are in two faces.
        self.assertGreater(sum(points.values()), len(points))

    def test_bad_input(self):
        output = self.path("out")
        for args, needle in [
                (["--face_size", "-1"], "face_size"),
                (["--fov_deg", "0"], "fov_deg"),
                (["--fov_deg", "180"], "fov_deg"),
                (["--faces", "front,sideways"], "sideways"),
                (["--output_type", "PMVS"], "output_type")]:
            result = self.export(output, *args, check=False)
            self.assertNotEqual(result.returncode, 0, args)
            self.assertIn(needle, result.stdout, args)
            self.assert_nothing_left(output)

        # A missing image is named; nothing half-written remains.
        os.rename(os.path.join(self.images, "pano2.png"),
                  os.path.join(self.images, "moved.png"))
        result = self.export(output, check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("pano2.png", result.stdout)
        self.assert_nothing_left(output)

        # An unreadable image found after the first one was written.
        with open(os.path.join(self.images, "pano2.png"), "wb") as f:
            f.write(b"not a png")
        result = self.export(output, check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("pano2.png", result.stdout)
        self.assert_nothing_left(output)


if __name__ == "__main__":
    unittest.main()
