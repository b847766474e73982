"""`colmap image_undistorter` on images of fisheye lenses beyond 180 degrees
(UNIFIED_OMNI, DOUBLE_SPHERE, OPENCV_FISHEYE): each becomes one PINHOLE view along the
optical axis that MVS can use, with the observations moved to where the view
sees their 3D points and the pixels resampled from the fisheye image.

Checked on a rendered room whose ground-truth model (exact projections of
known 3D points) is undistorted: every observation kept inside a view is the
PINHOLE projection of its 3D point, and the view's pixel there shows what
the fisheye image shows at the original observation."""
import math
import os

import numpy as np
from matplotlib import image as mpimg

from cli_util import TempDirTestCase, main_with_render
from sphera_common import (cam_from_world, model_to_text, read_text_model,
                           run_colmap, run_render)

SIZE = 512


def gray(path):
    """Image as float gray levels 0..255 (matplotlib reads PNG as 0..1)."""
    pixels = mpimg.imread(path).astype(np.float64)
    if pixels.max() <= 1.0:
        pixels = pixels * 255
    return pixels if pixels.ndim == 2 else pixels[..., :3].mean(axis=2)


class ImageUndistorterFisheyeTest(TempDirTestCase):
    def undistort(self, model, render_extra, *extra):
        scene = self.path("scene_" + model)
        run_render(scene, "--seed", "11", "--layout", "room9", "--model",
                   model, "--width", SIZE, "--height", SIZE, "--supersample",
                   "2", "--points", "1500", "--format", "png", *render_extra)
        output = self.path("dense_" + model)
        run_colmap("image_undistorter", "--image_path",
                   os.path.join(scene, "images"), "--input_path",
                   os.path.join(scene, "sparse_gt"), "--output_path", output,
                   *extra)
        source = read_text_model(os.path.join(scene, "sparse_gt"))
        views = read_text_model(model_to_text(os.path.join(output, "sparse"),
                                              output + "_txt"))
        return scene, output, source, views

    def check_views(self, model, max_half_angle_deg, *extra, render_extra=()):
        scene, output, source, views = self.undistort(model, render_extra,
                                                      *extra)
        src_cameras, src_images, points = source
        cameras, images, view_points = views
        self.assertEqual(len(images), len(src_images))
        self.assertEqual(len(view_points), len(points))

        for model_name, width, height, params in cameras.values():
            self.assertEqual((model_name, width, height),
                             ("PINHOLE", SIZE, SIZE))
            fx, fy, cx, cy = params
            half_x = math.degrees(math.atan(max(cx, width - cx) / fx))
            half_y = math.degrees(math.atan(max(cy, height - cy) / fy))
            # Within the cap, and not a needle: at least 40 degrees.
            self.assertLessEqual(max(half_x, half_y), max_half_angle_deg + 1e-6)
            self.assertGreater(max(half_x, half_y), 40)

        inside = behind = 0
        differences, shuffled = [], []
        rng = np.random.default_rng(1)
        for image_id, (fields, observations) in images.items():
            src_fields, src_observations = src_images[image_id]
            self.assertEqual(fields[1:10], src_fields[1:10])  # same pose, name
            self.assertEqual(len(observations), len(src_observations))
            fx, fy, cx, cy = cameras[int(fields[8])][3]
            rotation, translation = cam_from_world(fields)
            view = gray(os.path.join(output, "images", fields[9]))
            fisheye = gray(os.path.join(scene, "images", fields[9]))
            for (x, y, point_id), (sx, sy, _) in zip(observations,
                                                      src_observations):
                if point_id < 0:
                    continue
                in_cam = rotation @ np.array(points[point_id][0]) + translation
                if in_cam[2] <= 0:
                    # Behind the view's image plane: no pinhole pixel.
                    self.assertTrue(math.isnan(x) and math.isnan(y))
                    behind += 1
                    continue
                u = fx * in_cam[0] / in_cam[2] + cx
                v = fy * in_cam[1] / in_cam[2] + cy
                # Near the lens plane the coordinates grow without bound.
                self.assertAlmostEqual(x, u, delta=1e-3 + 1e-9 * abs(u))
                self.assertAlmostEqual(y, v, delta=1e-3 + 1e-9 * abs(v))
                if 3 <= x < SIZE - 3 and 3 <= y < SIZE - 3:
                    inside += 1
                    a = view[int(y), int(x)]
                    differences.append(abs(a - fisheye[int(sy), int(sx)]))
                    rx, ry = rng.integers(3, SIZE - 3, size=2)
                    shuffled.append(abs(a - fisheye[ry, rx]))
        self.assertGreater(inside, 500)
        self.assertGreater(behind, 100)  # the lenses see beyond 180 degrees
        # The view shows the fisheye's content at the moved observations:
        # far closer than at random pixels of the fisheye image.
        self.assertLess(np.median(differences), 0.25 * np.median(shuffled))
        print(f"image_undistorter {model}: {inside} observations inside the "
              f"views, {behind} behind them; median |view - fisheye| "
              f"{np.median(differences):.1f} vs {np.median(shuffled):.1f} "
              f"at random pixels")

    def test_unified_omni_190(self):
        self.check_views("UNIFIED_OMNI", 60)

    def test_double_sphere_with_a_narrower_cap(self):
        # --max_cam_point_norm caps the view's half-angle: tan(45 deg) = 1.
        self.check_views("DOUBLE_SPHERE", 45, "--max_cam_point_norm", "1")

    def test_opencv_fisheye_200(self):
        # Kannala-Brandt, 100 degrees from the axis at 0.48 of the image size:
        # COLMAP's own OPENCV_FISHEYE id beyond the hemisphere.
        self.check_views("OPENCV_FISHEYE", 60, render_extra=(
            "--camera_params", "142,142,256,256,0.01,-0.002,0,0"))


if __name__ == "__main__":
    main_with_render()
