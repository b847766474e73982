"""The 8-lens ring (Vuze-like: 8 outward 195° EUCM lenses on a 6 cm ring,
every other lens 1 cm higher) reconstructed as a rig through the colmap
program: rendered by sphera_render along 6 frames with 640-pixel lenses,
extracted one camera per lens with the image-circle masks, configured from
a start that knows the lenses' directions and intrinsics but none of their
offsets, matched and mapped. Checks every lens of every frame registered,
the poses against the ground truth and the recovered sensor_from_rig.
The issue's 0.5 mm for the lens centres needs more frames and pixels than a
test can afford: scripts/benchmark_rig.py --presets ring8 measures it."""
import json
import os

from cli_util import TempDirTestCase, main_with_render
from sphera_common import (aligned_pose_errors, extract_features,
                           match_exhaustive, median, model_to_text,
                           pose_errors, read_text_images, rig_errors,
                           rig_frame_poses, run_colmap, run_render,
                           text_model_poses, without_rig_offsets)

FRAMES = 6
LENSES = 8


class RingRigTest(TempDirTestCase):
    def test_every_frame_and_the_rig_of_eight_lenses(self):
        scene = self.path("scene")
        run_render(scene, "--rig_preset", "ring8", "--frames", FRAMES,
                   "--lens_size", 640, "--supersample", 2, "--seed", 0)
        images = os.path.join(scene, "images")
        self.assertEqual(len(os.listdir(images)), LENSES)

        database = self.path("database.db")
        extract_features(database, images, "EUCM", "--ImageReader.mask_path",
                         os.path.join(scene, "masks"),
                         "--ImageReader.single_camera_per_folder", "1",
                         single_camera=False)
        # What a user knows: the lenses' directions and intrinsics; every
        # lens centre starts at the reference lens's.
        with open(os.path.join(scene, "rig_config.json")) as f:
            config = without_rig_offsets(json.load(f))
        self.assertEqual(len(config[0]["cameras"]), LENSES)
        config_path = self.path("rig_config.json")
        with open(config_path, "w") as f:
            json.dump(config, f)
        run_colmap("rig_configurator", "--database_path", database,
                   "--rig_config_path", config_path)
        match_exhaustive(database)
        os.makedirs(self.path("sparse"))
        run_colmap("mapper", "--database_path", database, "--image_path",
                   images, "--output_path", self.path("sparse"))
        self.assertEqual(sorted(os.listdir(self.path("sparse"))), ["0"])
        model_to_text(self.path("sparse", "0"), self.path("text"))

        self.assertEqual(len(read_text_images(self.path("text"))),
                         LENSES * FRAMES, "every lens of every frame")
        gt = os.path.join(scene, "sparse_gt")
        # Per frame: lens 0's orientation and the mean of the lens centres
        # (a lens centre's error in the rig is checked below on its own).
        gt_frames = rig_frame_poses(text_model_poses(gt), LENSES)
        frames = rig_frame_poses(text_model_poses(self.path("text")), LENSES)
        self.assertEqual(sorted(frames), sorted(gt_frames))
        positions = [e[1] for e in
                     aligned_pose_errors(gt_frames, frames).values()]
        # Orientations per image, after the similarity of all 48 image
        # centres (6 frame centres on a loop pin the model's orientation
        # down less well: 0.0104 deg for every frame alike, measured).
        rotations = [e[0] for e in pose_errors(gt, self.path(
            "text")).values()]
        rig = rig_errors(gt, self.path("text"))
        print(f"ring8: image rotation median {median(rotations):.5f}, max "
              f"{max(rotations):.5f} deg; frame position median "
              f"{1000 * median(positions):.4f}, max "
              f"{1000 * max(positions):.4f} mm; sensor_from_rig (deg, mm)",
              {k: (round(r, 5), round(1000 * c, 3)) for k, (r, c) in
               sorted(rig.items())})
        # Measured here: images 0.0057 deg (max 0.0123), frames 0.072 mm
        # (max 0.095); lens rotations up to 0.0159 deg, lens centres 0.7 to
        # 1.7 mm.
        self.assertLess(median(rotations), 0.01)
        self.assertLess(max(rotations), 0.02)
        self.assertLess(max(positions), 0.001)
        self.assertEqual(len(rig), LENSES)
        for lens, (rotation, centre) in rig.items():
            self.assertLess(rotation, 0.02, lens)
            # From a start 6 cm off: within 3 mm here, 0.5 mm is the
            # benchmark's target with 10 frames of larger lenses.
            self.assertLess(centre, 0.003, lens)


if __name__ == "__main__":
    main_with_render()
