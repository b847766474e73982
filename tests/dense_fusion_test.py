"""COLMAP's own dense code accepts the workspace that `colmap
sphere_undistorter` exports from panoramas. patch_match_stereo needs CUDA, so
the depth and normal maps it would write are made here from the renderer's
ground-truth range maps (the panorama's range along each face pixel's ray, in
COLMAP's depth map format and pixel convention); `colmap stereo_fusion`
(CPU) then has to find them consistent across the faces of different
panoramas and fuse points on the true surface. This checks the workspace's
form (model, configuration, file names, depth map and pixel conventions);
that each face image shows what its pose sees is checked, to 0.5 px, by
sphere_undistorter_cli_test.py and export_retriangulation_test.py."""
import math
import os
import struct

from cli_util import TempDirTestCase, main_with_render
from sphera_common import (mat_vec, model_to_text, read_text_model,
                           rotation_matrix, run_colmap, run_render, transpose)


def mat_t_vec(m, v):
    """m transposed times v."""
    return mat_vec(transpose(m), v)


def pose(fields):
    """(cam_from_world rotation matrix, camera centre) of an images.txt line."""
    rotation = rotation_matrix(*(float(v) for v in fields[1:5]))
    t = [float(v) for v in fields[5:8]]
    return rotation, [-c for c in mat_t_vec(rotation, t)]


class RangeMap:
    """A sphera_render range map: int32 width, height, then float32 rows."""

    def __init__(self, path):
        with open(path, "rb") as f:
            self.width, self.height = struct.unpack("<2i", f.read(8))
            self.values = struct.unpack(f"<{self.width * self.height}f",
                                        f.read(4 * self.width * self.height))

    def at_ray(self, ray):
        """Bilinear range along a ray in the panorama's frame (0 = none).
        Values are at pixel centres (i + 0.5, j + 0.5); x wraps around."""
        x, y, z = ray
        u = (math.atan2(x, z) / (2 * math.pi) + 0.5) * self.width - 0.5
        v = (0.5 - math.atan2(-y, math.hypot(x, z)) / math.pi) * self.height
        v = min(max(v - 0.5, 0.0), self.height - 1.0)
        i0, j0 = math.floor(u), min(int(v), self.height - 2)
        a, b = u - i0, v - j0
        total = 0.0
        for di, dj, weight in ((0, 0, (1 - a) * (1 - b)), (1, 0, a * (1 - b)),
                               (0, 1, (1 - a) * b), (1, 1, a * b)):
            value = self.values[(j0 + dj) * self.width + (i0 + di) % self.width]
            if value <= 0:
                return 0.0
            total += weight * value
        return total


def write_colmap_mat(path, width, height, channels):
    """COLMAP's mvs::Mat file: 'width&height&depth&', then float32 values,
    channel planes of row-major pixels."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(f"{width}&{height}&{len(channels)}&".encode())
        for channel in channels:
            f.write(struct.pack(f"<{len(channel)}f", *channel))


def read_ply_points(path):
    """[(x, y, z)] of COLMAP's fused.ply."""
    with open(path, "rb") as f:
        header = []
        while True:
            line = f.readline().decode().strip()
            header.append(line)
            if line == "end_header":
                break
        assert "format binary_little_endian 1.0" in header, header
        count = int(next(l.split()[2] for l in header
                         if l.startswith("element vertex")))
        types = [l.split()[1] for l in header if l.startswith("property")]
        names = [l.split()[2] for l in header if l.startswith("property")]
        fmt = "<" + "".join({"float": "f", "uchar": "B"}[t] for t in types)
        size = struct.calcsize(fmt)
        data = f.read(count * size)
    keep = [names.index(n) for n in ("x", "y", "z")]
    return [tuple(values[k] for k in keep) for values in
            (struct.unpack_from(fmt, data, k * size) for k in range(count))]


class DenseFusionTest(TempDirTestCase):
    def test_stereo_fusion_fuses_exported_faces_on_the_true_surface(self):
        scene = self.path("scene")
        # Ground-truth points too: COLMAP's fusion takes each face's
        # neighbours from the sparse points it shares with them.
        run_render(scene, "--layout", "room9", "--model", "EQUIRECTANGULAR",
                   "--width", "512", "--height", "256", "--supersample", "1",
                   "--seed", "5", "--points", "3000")
        dense = self.path("dense")
        run_colmap("sphere_undistorter", "--input_path",
                   os.path.join(scene, "sparse_gt"), "--image_path",
                   os.path.join(scene, "images"), "--output_path", dense,
                   "--face_size", 96)
        faces_cameras, faces, _ = read_text_model(model_to_text(
            os.path.join(dense, "sparse"), self.path("faces_txt")))
        _, panoramas, _ = read_text_model(os.path.join(scene, "sparse_gt"))
        panos = []
        for fields, _ in panoramas.values():
            rotation, centre = pose(fields)
            panos.append((rotation, centre, RangeMap(os.path.join(
                scene, "depth", fields[9] + ".depth.bin"))))
        self.assertEqual(len(faces), 6 * len(panos))

        for fields, _ in faces.values():
            model, width, height, (fx, fy, cx, cy) = \
                faces_cameras[int(fields[8])]
            self.assertEqual(model, "PINHOLE")
            face_rotation, centre = pose(fields)
            # The panorama the face was cut from: the one at its centre.
            pano_rotation, _, ranges = min(
                panos, key=lambda p: sum((a - b) ** 2
                                         for a, b in zip(p[1], centre)))
            # COLMAP's dense code puts pixel (col, row) at K^-1 (col, row, 1).
            points = []
            for row in range(height):
                for col in range(width):
                    ray = [(col - cx) / fx, (row - cy) / fy, 1.0]
                    distance = ranges.at_ray(mat_vec(
                        pano_rotation, mat_t_vec(face_rotation, ray)))
                    depth = distance / math.sqrt(ray[0] ** 2 + ray[1] ** 2 + 1)
                    points.append([depth * ray[0], depth * ray[1], depth])
            normals = [[], [], []]
            for row in range(height):
                for col in range(width):
                    p = points[row * width + col]
                    q = points[row * width + min(col + 1, width - 1)]
                    r = points[min(row + 1, height - 1) * width + col]
                    if col == width - 1:
                        q = [2 * a - b for a, b in
                             zip(p, points[row * width + col - 1])]
                    if row == height - 1:
                        r = [2 * a - b for a, b in
                             zip(p, points[(row - 1) * width + col])]
                    du = [a - b for a, b in zip(q, p)]
                    dv = [a - b for a, b in zip(r, p)]
                    n = [du[1] * dv[2] - du[2] * dv[1],
                         du[2] * dv[0] - du[0] * dv[2],
                         du[0] * dv[1] - du[1] * dv[0]]
                    norm = math.sqrt(sum(c * c for c in n)) or 1.0
                    if sum(a * b for a, b in zip(n, p)) > 0:
                        norm = -norm
                    for k in range(3):
                        normals[k].append(n[k] / norm)
            name = fields[9]
            write_colmap_mat(os.path.join(dense, "stereo", "depth_maps",
                                          name + ".geometric.bin"),
                             width, height, [[p[2] for p in points]])
            write_colmap_mat(os.path.join(dense, "stereo", "normal_maps",
                                          name + ".geometric.bin"),
                             width, height, normals)

        fused = self.path("fused.ply")
        log = run_colmap("stereo_fusion", "--workspace_path", dense,
                         "--input_type", "geometric", "--output_path",
                         fused).stdout
        self.assertNotIn("Ignoring image", log)
        points = read_ply_points(fused)
        # Distance to the true surface: against the range map of the
        # panorama that sees the point best (the others may be occluded).
        errors = []
        for point in points[::max(1, len(points) // 3000)]:
            best = math.inf
            for rotation, centre, ranges in panos:
                offset = [a - b for a, b in zip(point, centre)]
                expected = ranges.at_ray(mat_vec(rotation, offset))
                if expected > 0:
                    best = min(best, abs(math.sqrt(sum(
                        c * c for c in offset)) - expected))
            errors.append(best)
        errors.sort()
        median, p90 = errors[len(errors) // 2], errors[int(0.9 * len(errors))]
        print(f"stereo_fusion: {len(points)} points from {len(faces)} faces; "
              f"distance to the surface median {median * 1000:.2f} mm, "
              f"90% {p90 * 1000:.2f} mm")
        # Every fused point needs 5 consistent pixels of different faces.
        self.assertGreater(len(points), 10000)
        self.assertLess(median, 0.005)
        self.assertLess(p90, 0.02)


if __name__ == "__main__":
    main_with_render()
