"""The new camera models through the real `colmap` program: model files in
text and binary (interchangeable with upstream COLMAP 4.1), and clear errors
with a non-zero exit for bad camera input, leaving the database intact."""
import os
import struct
import unittest

from cli_util import Database, TempDirTestCase, write_noise_image
from sphera_common import (CPU_EXTRACTION, EXTRACTION, read_text_cameras,
                           run_colmap)

# One camera of every new model, with the ids upstream COLMAP 4.1 and our
# README use.
NEW_MODEL_CAMERAS = [
    (1, "EUCM", 16, 1000, 800, [310.5, 311.25, 500.125, 400.5, 0.6, 1.1]),
    (2, "EQUIRECTANGULAR", 17, 5376, 2688, [5376, 2688]),
    (3, "UNIFIED_OMNI", 64, 1024, 1024,
     [280.5, 281.5, 512.25, 511.75, 1.05, -0.02, 0.003, 0.0004, -0.0002]),
    (4, "DOUBLE_SPHERE", 65, 1280, 1024,
     [350.0, 351.0, 640.5, 512.5, -0.2, 0.6]),
]


def write_text_model(path, cameras):
    os.makedirs(path)
    with open(os.path.join(path, "cameras.txt"), "w") as f:
        # The header upstream COLMAP 4.1 writes.
        f.write("# Camera list with one line of data per camera:\n"
                "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                f"# Number of cameras: {len(cameras)}\n")
        for camera_id, name, _, width, height, params in cameras:
            f.write(f"{camera_id} {name} {width} {height} "
                    + " ".join(repr(float(p)) for p in params) + "\n")
    with open(os.path.join(path, "images.txt"), "w") as f:
        for camera_id, *_ in cameras:
            f.write(f"{camera_id} 1 0 0 0 {camera_id * 0.5} 0.25 -1 "
                    f"{camera_id} image{camera_id}.jpg\n")
            f.write(f"100.5 200.25 1\n")
    with open(os.path.join(path, "points3D.txt"), "w") as f:
        track = " ".join(f"{camera_id} 0" for camera_id, *_ in cameras)
        f.write(f"1 0.5 0.25 3.0 128 64 32 0.5 {track}\n")


def read_binary_cameras(path):
    cameras = {}
    with open(os.path.join(path, "cameras.bin"), "rb") as f:
        (num_cameras,) = struct.unpack("<Q", f.read(8))
        for _ in range(num_cameras):
            camera_id, model_id, width, height = struct.unpack(
                "<IiQQ", f.read(24))
            cameras[camera_id] = (model_id, width, height)
            num_params = {16: 6, 17: 2, 64: 9, 65: 6}[model_id]
            f.read(8 * num_params)
    return cameras


class ModelFilesTest(TempDirTestCase):
    def test_text_binary_text_round_trip_keeps_every_new_model(self):
        write_text_model(self.path("txt"), NEW_MODEL_CAMERAS)
        os.makedirs(self.path("bin"))
        os.makedirs(self.path("txt2"))
        run_colmap("model_converter", "--input_path", self.path("txt"),
                   "--output_path", self.path("bin"), "--output_type", "BIN")
        binary = read_binary_cameras(self.path("bin"))
        for camera_id, _, model_id, width, height, _ in NEW_MODEL_CAMERAS:
            self.assertEqual(binary[camera_id], (model_id, width, height))
        run_colmap("model_converter", "--input_path", self.path("bin"),
                   "--output_path", self.path("txt2"), "--output_type", "TXT")
        round_trip = read_text_cameras(self.path("txt2"))
        for camera_id, name, _, width, height, params in NEW_MODEL_CAMERAS:
            self.assertEqual(round_trip[camera_id],
                             (name, width, height, params))

    def test_reads_upstream_equirectangular_cameras_file(self):
        upstream = [(7, "EQUIRECTANGULAR", 17, 4096, 2048, [4096, 2048])]
        write_text_model(self.path("upstream"), upstream)
        os.makedirs(self.path("bin"))
        run_colmap("model_converter", "--input_path", self.path("upstream"),
                   "--output_path", self.path("bin"), "--output_type", "BIN")
        self.assertEqual(read_binary_cameras(self.path("bin")),
                         {7: (17, 4096, 2048)})

    def test_wrong_parameter_count_in_model_file_is_rejected(self):
        bad = [(1, "EQUIRECTANGULAR", 17, 4096, 2048, [4096])]
        write_text_model(self.path("bad"), bad)
        os.makedirs(self.path("out"))
        result = run_colmap("model_converter", "--input_path",
                            self.path("bad"), "--output_path",
                            self.path("out"), "--output_type", "BIN",
                            check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertFalse(os.path.exists(self.path("out", "cameras.bin")))


class FeatureExtractionInputTest(TempDirTestCase):
    def setUp(self):
        super().setUp()
        os.makedirs(self.path("images"))
        for index in range(3):
            write_noise_image(self.path("images", f"pano{index}.pgm"), 512,
                              256, seed=index)
        self.database = self.path("database.db")

    def extract(self, *extra, check=True):
        return run_colmap("feature_extractor", "--database_path",
                          self.database, "--image_path", self.path("images"),
                          *CPU_EXTRACTION,
                          f"--{EXTRACTION}.num_threads", "2", *extra,
                          check=check)

    def assert_rejected(self, expected_text, *extra):
        result = self.extract(*extra, check=False)
        self.assertNotEqual(result.returncode, 0, result.stdout[-2000:])
        self.assertIn(expected_text, result.stdout)
        return result

    def test_equirectangular_images_get_model_17_and_their_size(self):
        self.extract("--ImageReader.camera_model", "EQUIRECTANGULAR")
        database = Database(self.database)
        cameras = database.cameras()
        self.assertEqual(len(database.images()), 3)
        for model, width, height, params in cameras.values():
            self.assertEqual((model, width, height, params),
                             (17, 512, 256, [512.0, 256.0]))
        self.assertTrue(all(n > 50 for n in database.num_keypoints().values()))
        database.close()

    def test_files_that_are_not_images_are_skipped(self):
        with open(self.path("images", "README.md"), "w") as f:
            f.write("notes about these images\n")
        self.extract("--ImageReader.camera_model", "EQUIRECTANGULAR")
        database = Database(self.database)
        self.assertEqual(len(database.images()), 3)
        database.close()

    def test_unknown_model_is_named(self):
        self.assert_rejected("NOT_A_MODEL", "--ImageReader.camera_model",
                             "NOT_A_MODEL")
        self.assertFalse(os.path.exists(self.database) and
                         Database(self.database).scalar(
                             "SELECT COUNT(*) FROM images"))

    def test_wrong_number_of_parameters(self):
        self.assert_rejected("expects 2", "--ImageReader.camera_model",
                             "EQUIRECTANGULAR", "--ImageReader.camera_params",
                             "512")

    def test_non_finite_parameter(self):
        self.assert_rejected("finite", "--ImageReader.camera_model", "PINHOLE",
                             "--ImageReader.camera_params", "nan,500,256,128")

    def test_equirectangular_width_must_be_twice_height(self):
        self.assert_rejected("twice", "--ImageReader.camera_model",
                             "EQUIRECTANGULAR", "--ImageReader.camera_params",
                             "500,256")

    def test_bad_images_are_named_and_existing_data_kept(self):
        self.extract("--ImageReader.camera_model", "EQUIRECTANGULAR")
        before = Database(self.database)
        keypoints_before = before.num_keypoints()
        cameras_before = before.cameras()
        before.close()

        # One good new panorama, one of another size than the given params,
        # and one file that is not an image.
        write_noise_image(self.path("images", "pano3.pgm"), 512, 256, seed=3)
        write_noise_image(self.path("images", "wide.pgm"), 600, 300, seed=4)
        with open(self.path("images", "broken.jpg"), "wb") as f:
            f.write(b"\xff\xd8\xff\xe0 this is not a JPEG")
        result = self.assert_rejected(
            "wide.pgm", "--ImageReader.camera_model", "EQUIRECTANGULAR",
            "--ImageReader.camera_params", "512,256")
        self.assertIn("differ from the image size 600x300", result.stdout)
        self.assertIn("broken.jpg", result.stdout)

        after = Database(self.database)
        self.assertEqual(after.scalar("PRAGMA integrity_check"), "ok")
        keypoints_after = after.num_keypoints()
        for name, count in keypoints_before.items():
            self.assertEqual(keypoints_after[name], count)
        self.assertIn("pano3.pgm", keypoints_after)
        self.assertNotIn("wide.pgm", after.images())
        self.assertNotIn("broken.jpg", after.images())
        for camera_id, camera in cameras_before.items():
            self.assertEqual(after.cameras()[camera_id], camera)
        after.close()


if __name__ == "__main__":
    unittest.main()
