"""Re-triangulating the model that `colmap sphere_undistorter` exports, with
COLMAP's own `point_triangulator` on the PINHOLE cube faces, reproduces the
exported sparse points: the face poses, intrinsics and observations are
consistent with each other and with the panoramas' ground truth."""
import math
import os
import sqlite3
import struct

from cli_util import TempDirTestCase, main_with_render
from sphera_common import (model_to_text, read_text_model, run_colmap,
                           run_render)

PINHOLE_MODEL_ID = 1
MAX_IMAGE_ID = 2147483647


def pair_id(image_id1, image_id2):
    return image_id1 * MAX_IMAGE_ID + image_id2


def write_database(path, cameras, images, points):
    """Cameras, images, keypoints (the POINTS2D) and, for every pair of images
    sharing 3D points, the exact correspondences as matches and verified
    two-view geometries."""
    run_colmap("database_creator", "--database_path", path)
    connection = sqlite3.connect(path)
    with connection:
        for camera_id, (model, width, height, params) in cameras.items():
            assert model == "PINHOLE", model
            connection.execute(
                "INSERT INTO cameras VALUES (?, ?, ?, ?, ?, ?)",
                (camera_id, PINHOLE_MODEL_ID, width, height,
                 struct.pack(f"<{len(params)}d", *params), 1))
        for image_id, (fields, observations) in images.items():
            connection.execute("INSERT INTO images VALUES (?, ?, ?)",
                               (image_id, fields[9], int(fields[8])))
            xy = [v for x, y, _ in observations for v in (x, y)]
            connection.execute(
                "INSERT INTO keypoints VALUES (?, ?, ?, ?)",
                (image_id, len(observations), 2,
                 struct.pack(f"<{len(xy)}f", *xy)))
        correspondences = {}
        for _, track in points.values():
            for a in range(len(track)):
                for b in range(a + 1, len(track)):
                    (i1, k1), (i2, k2) = sorted((track[a], track[b]))
                    if i1 != i2:
                        correspondences.setdefault((i1, i2), []).append(
                            (k1, k2))
        for (i1, i2), matches in correspondences.items():
            data = struct.pack(f"<{2 * len(matches)}I",
                               *[k for match in matches for k in match])
            connection.execute("INSERT INTO matches VALUES (?, ?, ?, ?)",
                               (pair_id(i1, i2), len(matches), 2, data))
            # config 2 = CALIBRATED; the matrices are not used here.
            connection.execute(
                "INSERT INTO two_view_geometries (pair_id, rows, cols, data, "
                "config, F, E, H, qvec, tvec) VALUES "
                "(?, ?, ?, ?, 2, ?, ?, ?, ?, ?)",
                (pair_id(i1, i2), len(matches), 2, data,
                 struct.pack("<9d", *[0.0] * 9),
                 struct.pack("<9d", *[0.0] * 9),
                 struct.pack("<9d", *[0.0] * 9),
                 struct.pack("<4d", 1.0, 0.0, 0.0, 0.0),
                 struct.pack("<3d", 0.0, 0.0, 0.0)))
    connection.close()
    return len(correspondences)


def write_model_without_points(path, cameras_path, images):
    """The exported model with an empty points3D.txt; POINTS2D keep x, y with
    POINT3D_ID -1."""
    os.makedirs(path)
    with open(cameras_path) as f, \
            open(os.path.join(path, "cameras.txt"), "w") as out:
        out.write(f.read())
    with open(os.path.join(path, "images.txt"), "w") as out:
        for image_id in sorted(images):
            fields, observations = images[image_id]
            out.write(" ".join(fields) + "\n")
            out.write(" ".join(f"{x!r} {y!r} -1"
                               for x, y, _ in observations) + "\n")
    open(os.path.join(path, "points3D.txt"), "w").close()


def panorama_of(image_name):
    """cam003_front.jpg -> cam003."""
    return image_name.rsplit("_", 1)[0]


class ExportRetriangulationTest(TempDirTestCase):
    def to_text(self, sparse, name):
        return model_to_text(sparse, self.path(name))

    def test_point_triangulator_reproduces_exported_points(self):
        scene = self.path("scene")
        run_render(scene, "--layout", "room9", "--model", "EQUIRECTANGULAR",
                   "--width", "1024", "--height", "512", "--supersample", "1",
                   "--points", "400", "--seed", "3")
        _, _, gt_points = read_text_model(os.path.join(scene, "sparse_gt"))

        workspace = self.path("workspace")
        run_colmap("sphere_undistorter", "--input_path",
                   os.path.join(scene, "sparse_gt"), "--image_path",
                   os.path.join(scene, "images"), "--output_path", workspace)
        exported_text = self.to_text(os.path.join(workspace, "sparse"),
                                     "exported")
        cameras, images, points = read_text_model(exported_text)
        self.assertEqual(len(images), 9 * 6)
        self.assertEqual(len(points), len(gt_points))

        # The export keeps the ground-truth points.
        for point_id, (xyz, _) in points.items():
            self.assertLess(math.dist(xyz, gt_points[point_id][0]), 1e-9)

        database = self.path("database.db")
        num_pairs = write_database(database, cameras, images, points)

        no_points = self.path("no_points")
        write_model_without_points(
            no_points, os.path.join(exported_text, "cameras.txt"), images)
        triangulated = self.path("triangulated")
        os.makedirs(triangulated)
        run_colmap("point_triangulator", "--database_path", database,
                   "--image_path", os.path.join(workspace, "images"),
                   "--input_path", no_points, "--output_path", triangulated,
                   "--Mapper.tri_ignore_two_view_tracks", "0",
                   # Keep face pairs with few shared points in the
                   # correspondence graph (default: 15 matches); the point
                   # filters keep their defaults.
                   "--Mapper.min_num_matches", "1")
        _, tri_images, tri_points = read_text_model(
            self.to_text(triangulated, "triangulated_text"))
        self.assertEqual(sorted(tri_images), sorted(images))

        # Points seen by faces of at least two different panoramas.
        coordinates = [xyz for xyz, _ in points.values()]
        scale = math.dist([min(c[i] for c in coordinates) for i in range(3)],
                          [max(c[i] for c in coordinates) for i in range(3)])
        tolerance = min(1e-3, 1e-4 * scale)  # metres
        names = {image_id: fields[9] for image_id, (fields, _) in
                 images.items()}
        num_candidates = num_reproduced = num_complete = 0
        max_error = 0.0
        for point_id, (xyz, track) in points.items():
            if len({panorama_of(names[i]) for i, _ in track}) < 2:
                continue
            num_candidates += 1
            tri_ids = {tri_images[i][1][k][2] for i, k in track}
            best = None
            for tri_id in tri_ids - {-1}:
                tri_xyz, tri_track = tri_points[tri_id]
                shared = set(tri_track) & set(track)
                if len({panorama_of(names[i]) for i, _ in shared}) < 2:
                    continue
                error = math.dist(tri_xyz, xyz)
                if best is None or error < best[0]:
                    best = (error, shared == set(track))
            if best is not None and best[0] < tolerance:
                num_reproduced += 1
                num_complete += best[1]
                max_error = max(max_error, best[0])
        print(f"export re-triangulation: {len(points)} exported points, "
              f"{num_candidates} seen by >= 2 panoramas, {num_reproduced} "
              f"reproduced within {tolerance:.2g} m ({num_complete} with the "
              f"full track), max error {max_error:.3g} m; {len(tri_points)} "
              f"re-triangulated points from {num_pairs} face pairs")
        self.assertGreaterEqual(num_candidates, 0.9 * len(points))
        # Measured: all 400 reproduced with their full tracks, within 1e-6 m.
        self.assertGreaterEqual(num_reproduced, 0.99 * num_candidates)


if __name__ == "__main__":
    main_with_render()
