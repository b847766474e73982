"""`colmap model_evaluator` and `colmap strecha_importer`: exact errors for
known perturbations, clear failures for bad input."""
import json
import math
import os
import random
import shutil
import struct

from cli_util import SHARED_DATA, TempDirTestCase
from sphera_common import (axis_angle_quat, pose_errors, quat_mul,
                           quat_rotate, run_colmap)

import unittest


class Pose:
    """cam_from_world as a unit quaternion (w, x, y, z) and a translation."""

    def __init__(self, q, t):
        self.q, self.t = q, t

    def center(self):
        q_inv = (self.q[0], -self.q[1], -self.q[2], -self.q[3])
        return tuple(-c for c in quat_rotate(q_inv, self.t))

    @staticmethod
    def from_center(q, center):
        return Pose(q, tuple(-c for c in quat_rotate(q, center)))


def write_model(path, poses, model_line="EQUIRECTANGULAR 2048 1024 2048 1024"):
    os.makedirs(path)
    with open(os.path.join(path, "cameras.txt"), "w") as f:
        f.write(f"1 {model_line}\n")
    with open(os.path.join(path, "images.txt"), "w") as f:
        for i, pose in enumerate(poses):
            f.write(f"{i + 1} {' '.join(map(repr, pose.q))} "
                    f"{' '.join(map(repr, pose.t))} 1 view{i}.jpg\n\n")
    open(os.path.join(path, "points3D.txt"), "w").close()


FOUNTAIN = os.path.join(SHARED_DATA, "strecha", "fountain-P11")


def import_fountain(output_path, *options):
    """The Strecha fountain's ground-truth cameras as a model at
    OUTPUT_PATH."""
    os.makedirs(output_path)
    run_colmap("strecha_importer", "--input_path",
               os.path.join(FOUNTAIN, "gt_dense_cameras"), "--output_path",
               output_path, *options)


def ground_truth_poses(count=9, seed=3):
    rng = random.Random(seed)
    poses = []
    for i in range(count):
        q = axis_angle_quat((rng.uniform(-1, 1), rng.uniform(-1, 1), 1),
                            rng.uniform(-0.5, 0.5))
        # A planar 3 x 3 grid: camera 4 sits exactly at the centroid.
        center = (float(i % 3) - 1, 0.0, float(i // 3) - 1)
        poses.append(Pose.from_center(q, center))
    return poses


def transformed(poses, scale, q_sim, t_sim, center_offsets=None):
    """POSES seen in the world x' = scale q_sim x + t_sim, the centre of
    image i first moved by center_offsets[i] (ground-truth units)."""
    center_offsets = center_offsets or {}
    estimate = []
    for i, pose in enumerate(poses):
        offset = center_offsets.get(i, (0.0, 0.0, 0.0))
        center = tuple(c + o for c, o in zip(pose.center(), offset))
        new_center = tuple(scale * c + t for c, t in
                           zip(quat_rotate(q_sim, center), t_sim))
        q_world = quat_mul(pose.q, (q_sim[0], -q_sim[1], -q_sim[2],
                                    -q_sim[3]))
        estimate.append(Pose.from_center(q_world, new_center))
    return estimate


class ModelEvaluatorTest(TempDirTestCase):
    def evaluate(self, gt, estimate, check=True, alignment=None):
        os.makedirs(self.path("out"), exist_ok=True)
        extra = ["--alignment", alignment] if alignment else []
        return run_colmap("model_evaluator", "--gt_path", gt, "--input_path",
                          estimate, "--output_path", self.path("out"),
                          *extra, check=check)

    def read_json(self):
        with open(self.path("out", "evaluation.json")) as f:
            return json.load(f)

    def test_ground_truth_against_itself_has_zero_error(self):
        write_model(self.path("gt"), ground_truth_poses())
        self.evaluate(self.path("gt"), self.path("gt"))
        result = self.read_json()
        self.assertEqual(result["num_registered"], 9)
        self.assertEqual(result["num_gt_images"], 9)
        self.assertLess(result["max_rotation_error_deg"], 1e-6)
        self.assertLess(result["max_position_error"], 1e-9)
        self.assertAlmostEqual(result["closest_pair_baseline"], 1.0, delta=0.25)

    def test_known_similarity_and_perturbations_are_measured(self):
        gt = ground_truth_poses()
        write_model(self.path("gt"), gt)
        # A similarity world change (scale 2.5, rotation, translation), then a
        # known rotation of one camera and a known centre offset of another.
        scale = 2.5
        q_sim = axis_angle_quat((0.3, -1, 0.2), 0.8)
        rotation_error_deg = 0.5
        offset = 0.02  # ground-truth units
        estimate = transformed(gt, scale, q_sim, (4.0, -2.0, 1.5),
                               {4: (offset, 0.0, 0.0)})
        estimate[7] = Pose.from_center(
            quat_mul(axis_angle_quat((0, 1, 0),
                                     math.radians(rotation_error_deg)),
                     estimate[7].q),
            estimate[7].center())
        write_model(self.path("estimate"), estimate)
        # Both protocols: the offset of the camera at the centroid changes
        # neither the centres' rotation nor the orientations' median.
        for alignment in ("centers", "orientations", None):
            with self.subTest(alignment=alignment):
                self.evaluate(self.path("gt"), self.path("estimate"),
                              alignment=alignment)
                result = self.read_json()
                self.assertEqual(result["alignment"],
                                 alignment or "centers")
                self.assertEqual(result["num_registered"], 9)
                by_name = {image["name"]: image
                           for image in result["images"]}
                self.assertAlmostEqual(
                    by_name["view7.jpg"]["rotation_error_deg"],
                    rotation_error_deg, delta=1e-6)
                for name, image in by_name.items():
                    if name != "view7.jpg":
                        self.assertLess(image["rotation_error_deg"], 1e-6,
                                        name)
                # The least-squares similarity spreads the offset of the
                # camera at the centroid over all nine (its rotation and, to
                # first order, its scale are unaffected): that camera keeps
                # 8/9 of it, every other 1/9.
                self.assertAlmostEqual(by_name["view4.jpg"]["position_error"],
                                       offset * 8 / 9, delta=2e-4)
                self.assertAlmostEqual(by_name["view0.jpg"]["position_error"],
                                       offset / 9, delta=2e-4)

    def test_protocols_differ_as_predicted(self):
        # Centre offsets off the centroid tilt the least-squares similarity
        # of the centres, so under "centers" every camera shows the same
        # rotation error, which an independent Umeyama alignment predicts;
        # under "orientations" the (exact) orientations fix the rotation:
        # no rotation error, positions from least squares with the true
        # rotation.
        import numpy as np
        gt = ground_truth_poses()
        write_model(self.path("gt"), gt)
        q_sim = axis_angle_quat((1, 0.5, -0.2), 0.4)
        t_sim = (1.0, 2.0, -3.0)
        offsets = {0: (0.0, 0.06, 0.0), 2: (0.0, -0.04, 0.03),
                   8: (0.05, 0.0, -0.02)}
        write_model(self.path("estimate"),
                    transformed(gt, 1.7, q_sim, t_sim, offsets))

        self.evaluate(self.path("gt"), self.path("estimate"),
                      alignment="centers")
        centers = {image["name"]: image
                   for image in self.read_json()["images"]}
        expected = pose_errors(self.path("gt"), self.path("estimate"))
        self.assertEqual(set(centers), set(expected))
        tilt = max(rotation for rotation, _ in expected.values())
        self.assertGreater(tilt, 0.1)  # degrees: the protocols must differ
        for name, (rotation, position) in expected.items():
            self.assertAlmostEqual(centers[name]["rotation_error_deg"],
                                   rotation, delta=0.01 * rotation + 1e-9)
            self.assertAlmostEqual(centers[name]["position_error"], position,
                                   delta=0.01 * position + 1e-9)

        self.evaluate(self.path("gt"), self.path("estimate"),
                      alignment="ORIENTATIONS")
        orientations = {image["name"]: image
                        for image in self.read_json()["images"]}
        gt_centres = np.array([pose.center() for pose in gt])
        est = transformed(gt, 1.7, q_sim, t_sim, offsets)
        # Undo the known world rotation, then least-squares scale and shift.
        q_inv = (q_sim[0], -q_sim[1], -q_sim[2], -q_sim[3])
        est_centres = np.array([quat_rotate(q_inv, pose.center())
                                for pose in est])
        g = gt_centres - gt_centres.mean(0)
        e = est_centres - est_centres.mean(0)
        scale = (g * e).sum() / (e * e).sum()
        for i in range(len(gt)):
            name = f"view{i}.jpg"
            self.assertLess(orientations[name]["rotation_error_deg"], 1e-6)
            self.assertAlmostEqual(orientations[name]["position_error"],
                                   float(np.linalg.norm(scale * e[i] - g[i])),
                                   delta=1e-7)

    def test_unknown_alignment_is_named(self):
        write_model(self.path("gt"), ground_truth_poses())
        result = self.evaluate(self.path("gt"), self.path("gt"), check=False,
                               alignment="median")
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("alignment", result.stdout)
        self.assertFalse(os.path.exists(self.path("out", "evaluation.json")))

    def test_unregistered_images_are_counted(self):
        gt = ground_truth_poses()
        write_model(self.path("gt"), gt)
        write_model(self.path("estimate"), gt[:5])
        self.evaluate(self.path("gt"), self.path("estimate"))
        result = self.read_json()
        self.assertEqual((result["num_registered"], result["num_gt_images"]),
                         (5, 9))
        self.assertEqual(sum(not image["registered"]
                             for image in result["images"]), 4)

    def test_fewer_than_three_common_images_fail_cleanly(self):
        gt = ground_truth_poses()
        write_model(self.path("gt"), gt)
        write_model(self.path("estimate"), gt[:2])
        result = self.evaluate(self.path("gt"), self.path("estimate"),
                               check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("at least 3", result.stdout)
        self.assertFalse(os.path.exists(self.path("out", "evaluation.json")))

    def test_negative_or_non_finite_threshold_is_named(self):
        write_model(self.path("gt"), ground_truth_poses())
        os.makedirs(self.path("out"))
        for value in ("-1", "nan", "inf"):
            with self.subTest(value=value):
                result = run_colmap(
                    "model_evaluator", "--gt_path", self.path("gt"),
                    "--input_path", self.path("gt"), "--output_path",
                    self.path("out"), "--max_proj_center_error", value,
                    check=False)
                self.assertEqual(result.returncode, 1, result.stdout)
                self.assertIn("max_proj_center_error", result.stdout)
                self.assertEqual(os.listdir(self.path("out")), [])

    def test_damaged_depth_maps_are_named(self):
        # Range maps of the ground truth's 64x32 images: one holding a NaN,
        # one a negative range, one of another size; each is named with its
        # file, and no evaluation is written.
        write_model(self.path("gt"), ground_truth_poses(),
                    model_line="EQUIRECTANGULAR 64 32 64 32")
        os.makedirs(self.path("out"))
        cases = (("nan", (64, 32), float("nan"), "range nan"),
                 ("negative", (64, 32), -2.0, "range -2"),
                 ("size", (32, 16), 1.0, "is 32x16"))
        for tag, (width, height), bad, reason in cases:
            with self.subTest(case=tag):
                depth = self.path(f"depth_{tag}")
                os.makedirs(depth)
                for i in range(9):
                    ranges = [2.0] * (width * height)
                    if i == 4:
                        ranges[width * 3 + 5] = bad
                    with open(os.path.join(depth, f"view{i}.jpg.depth.bin"),
                              "wb") as f:
                        f.write(struct.pack("<2i", width, height))
                        f.write(struct.pack(f"<{len(ranges)}f", *ranges))
                result = run_colmap(
                    "model_evaluator", "--gt_path", self.path("gt"),
                    "--input_path", self.path("gt"), "--output_path",
                    self.path("out"), "--depth_path", depth, check=False)
                self.assertEqual(result.returncode, 1, result.stdout)
                self.assertIn(reason, result.stdout)
                # Every map of the size case is wrong; the first read is
                # named, whichever it is.
                self.assertIn("view4.jpg.depth.bin" if tag != "size"
                              else ".jpg.depth.bin", result.stdout)
                self.assertEqual(os.listdir(self.path("out")), [])

    def test_malformed_model_fails_cleanly(self):
        write_model(self.path("gt"), ground_truth_poses())
        write_model(self.path("estimate"), ground_truth_poses())
        with open(self.path("estimate", "images.txt"), "w") as f:
            f.write("1 not a pose\n\n")
        result = self.evaluate(self.path("gt"), self.path("estimate"),
                               check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn(self.path("estimate"), result.stdout)
        self.assertFalse(os.path.exists(self.path("out", "evaluation.json")))

    @unittest.skipUnless(os.path.isdir(FOUNTAIN), "needs ../shared/data")
    def test_centers_protocol_is_the_least_squares_similarity(self):
        # The Strecha fountain's ground truth, each camera moved by noise
        # (centres 2 cm, orientations 0.1 degrees) and the world by a
        # similarity: "centers" measures what an independent least-squares
        # similarity of the centres (Umeyama) gives, within 1%.
        import_fountain(self.path("gt"), "--output_type", "TXT")
        rng = random.Random(11)
        q_sim = axis_angle_quat((0.2, 1, -0.4), 1.1)
        t_sim = (3.0, 0.5, -7.0)
        with open(self.path("gt", "images.txt")) as f:
            lines = [l.split() for l in f
                     if not l.startswith("#") and len(l.split()) == 10]
        self.assertEqual(len(lines), 11)
        estimate = []
        for fields in lines:
            pose = Pose(tuple(map(float, fields[1:5])),
                        tuple(map(float, fields[5:8])))
            noisy = Pose.from_center(
                quat_mul(axis_angle_quat(
                    (rng.gauss(0, 1), rng.gauss(0, 1), rng.gauss(0, 1)),
                    math.radians(0.1)), pose.q),
                tuple(c + rng.gauss(0, 0.02) for c in pose.center()))
            moved = transformed([noisy], 0.3, q_sim, t_sim)[0]
            estimate.append((fields[0], moved, fields[8], fields[9]))
        os.makedirs(self.path("estimate"))
        for name in ("cameras.txt", "points3D.txt"):
            shutil.copy(self.path("gt", name), self.path("estimate", name))
        with open(self.path("estimate", "images.txt"), "w") as f:
            for image_id, pose, camera_id, name in estimate:
                f.write(f"{image_id} {' '.join(map(repr, pose.q))} "
                        f"{' '.join(map(repr, pose.t))} {camera_id} {name}"
                        "\n\n")
        os.makedirs(self.path("out"))
        run_colmap("model_evaluator", "--gt_path", self.path("gt"),
                   "--input_path", self.path("estimate"), "--output_path",
                   self.path("out"), "--alignment", "centers")
        measured = {image["name"]: image for image in self.read_json()["images"]}
        expected = pose_errors(self.path("gt"), self.path("estimate"))
        self.assertEqual(len(expected), 11)
        for name, (rotation, position) in expected.items():
            self.assertGreater(position, 1e-3, name)  # the noise is measured
            self.assertAlmostEqual(measured[name]["rotation_error_deg"],
                                   rotation, delta=0.01 * rotation)
            self.assertAlmostEqual(measured[name]["position_error"], position,
                                   delta=0.01 * position)


class StrechaImporterTest(TempDirTestCase):
    def write_camera(self, name, text):
        os.makedirs(self.path("cams"), exist_ok=True)
        with open(self.path("cams", name + ".camera"), "w") as f:
            f.write(text)

    def test_convention_and_values(self):
        # R (camera-to-world) = rotation of 90 degrees about z, centre C.
        self.write_camera("a.jpg", "1000 0 500\n0 1100 400\n0 0 1\n0 0 0\n"
                          "0 -1 0\n1 0 0\n0 0 1\n1 2 3\n1000 800\n")
        os.makedirs(self.path("model"))
        run_colmap("strecha_importer", "--input_path", self.path("cams"),
                   "--output_path", self.path("model"))
        with open(self.path("model", "cameras.txt")) as f:
            camera = [l for l in f if not l.startswith("#")][0].split()
        self.assertEqual(camera[1:], ["PINHOLE", "1000", "800", "1000", "1100",
                                      "500", "400"])
        with open(self.path("model", "images.txt")) as f:
            image = [l for l in f if not l.startswith("#")][0].split()
        q = tuple(map(float, image[1:5]))
        t = tuple(map(float, image[5:8]))
        center = Pose(q, t).center()
        for got, expected in zip(center, (1, 2, 3)):
            self.assertAlmostEqual(got, expected, places=9)
        # cam_from_world = R^T: the world x axis is the camera's -y axis.
        x_in_cam = quat_rotate(q, (1, 0, 0))
        for got, expected in zip(x_in_cam, (0, -1, 0)):
            self.assertAlmostEqual(got, expected, places=9)
        self.assertEqual(image[9], "a.jpg")

    def test_malformed_file_is_named(self):
        self.write_camera("bad.jpg", "1000 0 500\n0 1100\n")
        os.makedirs(self.path("model"))
        result = run_colmap("strecha_importer", "--input_path",
                            self.path("cams"), "--output_path",
                            self.path("model"), check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("bad.jpg.camera:2", result.stdout)

    def test_non_finite_values_are_named(self):
        # A NaN focal length, an infinite rotation entry, a NaN centre: each
        # names its file and line, and nothing is written.
        valid = ["1000 0 500", "0 1100 400", "0 0 1", "0 0 0", "0 -1 0",
                 "1 0 0", "0 0 1", "1 2 3", "1000 800"]
        for line, value in ((0, "nan 0 500"), (5, "1 inf 0"),
                            (7, "1 nan 3")):
            with self.subTest(line=line + 1):
                shutil.rmtree(self.path("cams"), ignore_errors=True)
                lines = list(valid)
                lines[line] = value
                self.write_camera("c.jpg", "\n".join(lines) + "\n")
                os.makedirs(self.path(f"model{line}"))
                result = run_colmap("strecha_importer", "--input_path",
                                    self.path("cams"), "--output_path",
                                    self.path(f"model{line}"), check=False)
                self.assertNotEqual(result.returncode, 0)
                self.assertIn(f"c.jpg.camera:{line + 1}", result.stdout)
                self.assertIn("finite", result.stdout)
                self.assertEqual(os.listdir(self.path(f"model{line}")), [])

    def test_absurd_sizes_and_matrices_are_named(self):
        # A huge, a fractional and a zero image size; K not upper
        # triangular, not normalised, with a negative focal length, with its
        # principal point far outside the image: each names its file and
        # what is wrong, and nothing is written.
        valid = ["1000 0 500", "0 1100 400", "0 0 1", "0 0 0", "0 -1 0",
                 "1 0 0", "0 0 1", "1 2 3", "1000 800"]
        cases = ((8, "1000000000 800", "outside"),
                 (8, "1000.5 800", "whole number"),
                 (8, "1000 0", "outside"),
                 (2, "0 0.3 1", "upper triangular"),
                 (2, "0 0 2", "normalised"),
                 (0, "-1000 0 500", "positive"),
                 (1, "0 1100 90000", "outside the 1000x800 image"))
        for index, (line, value, reason) in enumerate(cases):
            with self.subTest(value=value):
                shutil.rmtree(self.path("cams"), ignore_errors=True)
                lines = list(valid)
                lines[line] = value
                self.write_camera("c.jpg", "\n".join(lines) + "\n")
                out = self.path(f"model{index}")
                os.makedirs(out)
                result = run_colmap("strecha_importer", "--input_path",
                                    self.path("cams"), "--output_path", out,
                                    check=False)
                self.assertEqual(result.returncode, 1, result.stdout)
                self.assertIn("c.jpg.camera", result.stdout)
                self.assertIn(reason, result.stdout)
                self.assertEqual(os.listdir(out), [])

    @unittest.skipUnless(os.path.isdir(FOUNTAIN), "needs ../shared/data")
    def test_fountain_ground_truth_imports(self):
        import_fountain(self.path("model"))
        with open(self.path("model", "images.txt")) as f:
            names = [l.split()[9] for l in f
                     if not l.startswith("#") and len(l.split()) == 10]
        self.assertEqual(len(names), 11)
        self.assertIn("0000.jpg", names)


if __name__ == "__main__":
    unittest.main()
