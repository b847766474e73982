"""`colmap calibration_importer`: a hand-written sample of each format
(Kalibr camchain, OpenCV fisheye YAML and omnidir XML, OCamCalib
calib_results.txt, Basalt JSON) gives the expected --ImageReader options,
cameras.txt and rig_config.json, which rig_configurator accepts; bad files
are a one-line error naming the file and the field, exit 1, nothing
written."""
import json
import math
import os
import re
import struct

from cli_util import Database, TempDirTestCase, listing, write_noise_image
from sphera_common import CPU_EXTRACTION, run_colmap

import unittest

# cam1 is cam0 turned 90° about y (x1 = z0 + 0.1, z1 = -x0); cam2 is cam1
# turned 180° about y and moved 5 cm along cam1's z.
KALIBR = """cam0:
  camera_model: pinhole
  intrinsics: [458.654, 457.296, 367.215, 248.375]
  distortion_model: radtan
  distortion_coeffs: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
  resolution: [752, 480]
  rostopic: /cam0/image_raw
cam1:
  T_cn_cnm1:
  - [0.0, 0.0, 1.0, 0.1]
  - [0.0, 1.0, 0.0, 0.0]
  - [-1.0, 0.0, 0.0, 0.0]
  - [0.0, 0.0, 0.0, 1.0]
  camera_model: pinhole
  intrinsics: [350.0, 351.0, 639.5, 479.5]
  distortion_model: equidistant
  distortion_coeffs: [0.01, -0.002, 0.0003, -0.00004]
  resolution: [1280, 960]
  rostopic: /cam1/image_raw
cam2:
  T_cn_cnm1:
  - [-1.0, 0.0, 0.0, 0.0]
  - [0.0, 1.0, 0.0, 0.0]
  - [0.0, 0.0, -1.0, 0.05]
  - [0.0, 0.0, 0.0, 1.0]
  camera_model: omni
  intrinsics: [1.2, 700.0, 701.0, 511.5, 511.5]
  distortion_model: radtan
  distortion_coeffs: [-0.1, 0.02, 0.001, -0.002]
  resolution: [1024, 1024]
"""

KALIBR_DS_EUCM = """cam0:
  camera_model: ds
  intrinsics: [-0.2, 0.6, 300.0, 300.0, 511.5, 511.5]
  distortion_model: none
  distortion_coeffs: []
  resolution: [1024, 1024]
cam1:
  T_cn_cnm1:
  - [1.0, 0.0, 0.0, -0.03]
  - [0.0, 1.0, 0.0, 0.0]
  - [0.0, 0.0, 1.0, 0.0]
  - [0.0, 0.0, 0.0, 1.0]
  camera_model: eucm
  intrinsics: [0.6, 1.1, 310.0, 311.0, 511.5, 511.5]
  distortion_model: none
  distortion_coeffs: []
  resolution: [1024, 1024]
"""

OPENCV_FISHEYE = """%YAML:1.0
---
image_width: 1280
image_height: 960
fisheye_model: 1
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 330.5, 0., 639.5, 0., 331.5, 479.5, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 4
   cols: 1
   dt: d
   data: [ 0.021, -0.0051, 0.0009, -0.0001 ]
"""

OPENCV_OMNIDIR = """<?xml version="1.0"?>
<opencv_storage>
<image_width>1024</image_width>
<image_height>768</image_height>
<camera_matrix type_id="opencv-matrix">
  <rows>3</rows><cols>3</cols><dt>d</dt>
  <data>600. 0. 511.5 0. 601. 383.5 0. 0. 1.</data></camera_matrix>
<distortion_coefficients type_id="opencv-matrix">
  <rows>1</rows><cols>4</cols><dt>d</dt>
  <data>-0.2 0.05 0.001 0.0005</data></distortion_coefficients>
<xi type_id="opencv-matrix">
  <rows>1</rows><cols>1</cols><dt>d</dt>
  <data>1.1</data></xi>
</opencv_storage>
"""

OCAMCALIB = """#polynomial coefficients for the DIRECT mapping function (ocam_model.ss in MATLAB). These are used by cam2world

5 -2.500000e+02 0.000000e+00 1.200000e-03 -1.000000e-06 2.000000e-09 

#polynomial coefficients for the inverse mapping function (ocam_model.invpol in MATLAB). These are used by world2cam

3 250.0 100.0 10.0 

#center: "row" and "column", starting from 0 (C convention)

479.25 639.75

#affine parameters "c", "d", "e"

1.000500 0.000200 -0.000100

#image size: "height" and "width"

960 1280
"""

BASALT = {"value0": {
    "T_imu_cam": [
        {"px": 0.01, "py": 0.0, "pz": 0.0,
         "qx": 0.0, "qy": 0.0, "qz": 0.0, "qw": 1.0},
        {"px": -0.09, "py": 0.0, "pz": 0.0, "qx": 0.0,
         "qy": math.sqrt(0.5), "qz": 0.0, "qw": math.sqrt(0.5)}],
    "intrinsics": [
        {"camera_type": "kb4",
         "intrinsics": {"fx": 380.0, "fy": 381.0, "cx": 319.5, "cy": 239.5,
                        "k1": 0.01, "k2": -0.002, "k3": 0.0004,
                        "k4": -0.00005}},
        {"camera_type": "ds",
         "intrinsics": {"fx": 300.0, "fy": 300.0, "cx": 319.5, "cy": 239.5,
                        "xi": -0.2, "alpha": 0.6}}],
    "resolution": [[640, 480], [640, 480]],
    "vignette": [],
    "calib_accel_bias": [0.0] * 9,
    "calib_gyro_bias": [0.0] * 12}}


def image_reader_options(output):
    """{camera name: (model, [params])} of the printed --ImageReader lines."""
    cameras = {}
    name = None
    for line in output.splitlines():
        header = re.match(r"^(cam\d+): ", line)
        if header:
            name = header.group(1)
        options = re.match(r"^\s+--ImageReader.camera_model (\S+) "
                           r"--ImageReader.camera_params (\S+)$", line)
        if options:
            cameras[name] = (options.group(1),
                             [float(v) for v in options.group(2).split(",")])
    return cameras


def quat_rotate(q, v):
    w, x, y, z = q
    # v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z).
    u = (x, y, z)

    def cross(a, b):
        return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0])
    uv = cross(u, v)
    uuv = cross(u, uv)
    return tuple(v[i] + 2 * w * uv[i] + 2 * uuv[i] for i in range(3))


class CalibrationImporterTest(TempDirTestCase):
    def write(self, name, text):
        path = self.path(name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def run_importer(self, path, *options):
        # A new output folder for every run, also of the same file.
        self.runs = getattr(self, "runs", 0) + 1
        output = self.path(f"out{self.runs}_" +
                           os.path.basename(path).replace(".", "_"))
        os.makedirs(output)
        result = run_colmap("calibration_importer", "--input_path", path,
                            "--output_path", output, *options)
        return result.stdout, output

    def assert_params(self, actual, expected, places=12):
        self.assertEqual(len(actual), len(expected))
        for a, e in zip(actual, expected):
            self.assertAlmostEqual(a, e, places=places)

    def in_camera(self, camera, point):
        rotated = quat_rotate(camera["cam_from_rig_rotation"], point)
        return [r + t for r, t in zip(rotated,
                                      camera["cam_from_rig_translation"])]

    def test_kalibr_camchain(self):
        stdout, output = self.run_importer(self.write("camchain.yaml", KALIBR))
        cameras = image_reader_options(stdout)
        self.assertEqual(sorted(cameras), ["cam0", "cam1", "cam2"])
        # Principal points gain half a pixel (COLMAP counts from the corner).
        self.assertEqual(cameras["cam0"][0], "OPENCV")
        self.assert_params(cameras["cam0"][1],
                           [458.654, 457.296, 367.715, 248.875, -0.28340811,
                            0.07395907, 0.00019359, 1.76187114e-05])
        self.assertEqual(cameras["cam1"][0], "OPENCV_FISHEYE")
        self.assert_params(cameras["cam1"][1],
                           [350, 351, 640, 480, 0.01, -0.002, 0.0003,
                            -0.00004])
        self.assertEqual(cameras["cam2"][0], "UNIFIED_OMNI")
        self.assert_params(cameras["cam2"][1],
                           [700, 701, 512, 512, 1.2, -0.1, 0.02, 0.001,
                            -0.002])
        self.assertIn("(exact)", stdout)

        with open(os.path.join(output, "rig_config.json")) as f:
            config = json.load(f)
        self.assertEqual(len(config), 1)
        rig = config[0]["cameras"]
        self.assertEqual([c["image_prefix"] for c in rig],
                         ["cam0/", "cam1/", "cam2/"])
        self.assertTrue(rig[0]["ref_sensor"])
        self.assertNotIn("cam_from_rig_rotation", rig[0])
        self.assertEqual(rig[2]["camera_model_name"], "UNIFIED_OMNI")
        self.assert_params(rig[2]["camera_params"], cameras["cam2"][1])
        point = (0.3, -0.2, 1.0)
        self.assert_params(self.in_camera(rig[1], point), [1.1, -0.2, -0.3])
        self.assert_params(self.in_camera(rig[2], point), [-1.1, -0.2, 0.35])

        with open(os.path.join(output, "cameras.txt")) as f:
            lines = [line.split() for line in f if not line.startswith("#")]
        self.assertEqual([line[:4] for line in lines],
                         [["1", "OPENCV", "752", "480"],
                          ["2", "OPENCV_FISHEYE", "1280", "960"],
                          ["3", "UNIFIED_OMNI", "1024", "1024"]])

    def test_rig_configurator_accepts_the_rig_config(self):
        _, output = self.run_importer(
            self.write("camchain_ds.yaml", KALIBR_DS_EUCM))
        images = self.path("images")
        for camera in ("cam0", "cam1"):
            os.makedirs(os.path.join(images, camera))
            for frame in range(2):
                write_noise_image(
                    os.path.join(images, camera, f"frame{frame}.pgm"), 64, 64,
                    seed=frame * 2 + (camera == "cam1"))
        database = self.path("database.db")
        run_colmap("feature_extractor", "--database_path", database,
                   "--image_path", images,
                   "--ImageReader.single_camera_per_folder", "1",
                   *CPU_EXTRACTION)
        run_colmap("rig_configurator", "--database_path", database,
                   "--rig_config_path",
                   os.path.join(output, "rig_config.json"))
        db = Database(database)
        cameras = db.cameras()
        images_by_name = db.images()
        self.assertEqual(db.scalar("SELECT COUNT(*) FROM rigs"), 1)
        self.assertEqual(db.scalar("SELECT COUNT(*) FROM frames"), 2)
        (blob,) = db.connection.execute(
            "SELECT sensor_from_rig FROM rig_sensors").fetchone()
        db.close()
        # The cameras take the config's models (DOUBLE_SPHERE 65, EUCM 16).
        self.assertEqual(cameras[images_by_name["cam0/frame0.pgm"]][0], 65)
        self.assertEqual(cameras[images_by_name["cam1/frame1.pgm"]][0], 16)
        self.assert_params(cameras[images_by_name["cam1/frame1.pgm"]][3],
                           [310, 311, 512, 512, 0.6, 1.1])
        # cam1 from cam0: identity rotation, 3 cm along -x.
        values = struct.unpack("7d", blob)
        self.assert_params(sorted(abs(v) for v in values[:4]), [0, 0, 0, 1])
        self.assert_params(values[4:], [-0.03, 0, 0])

    def test_opencv_fisheye_and_omnidir(self):
        stdout, output = self.run_importer(
            self.write("fisheye.yml", OPENCV_FISHEYE))
        cameras = image_reader_options(stdout)
        self.assertEqual(cameras["cam0"][0], "OPENCV_FISHEYE")
        self.assert_params(cameras["cam0"][1],
                           [330.5, 331.5, 640, 480, 0.021, -0.0051, 0.0009,
                            -0.0001])
        # One camera: no rig config.
        self.assertEqual(sorted(os.listdir(output)), ["cameras.txt"])
        # An output folder that does not exist yet is made; one whose
        # parent does not exist is named.
        new = self.path("new_folder")
        run_colmap("calibration_importer", "--input_path",
                   self.write("fisheye2.yml", OPENCV_FISHEYE),
                   "--output_path", new)
        self.assertEqual(os.listdir(new), ["cameras.txt"])
        result = run_colmap("calibration_importer", "--input_path",
                            self.write("fisheye3.yml", OPENCV_FISHEYE),
                            "--output_path", self.path("no/such"),
                            check=False)
        self.assertEqual(result.returncode, 1)
        self.assertIn("--output_path " + self.path("no/such"), result.stdout)
        self.assertFalse(os.path.exists(self.path("no")))

        stdout, _ = self.run_importer(self.write("omni.xml", OPENCV_OMNIDIR))
        cameras = image_reader_options(stdout)
        self.assertEqual(cameras["cam0"][0], "UNIFIED_OMNI")
        self.assert_params(cameras["cam0"][1],
                           [600, 601, 512, 384, 1.1, -0.2, 0.05, 0.001,
                            0.0005])

    def test_ocamcalib_and_conversion_to_opencv_fisheye(self):
        path = self.write("calib_results.txt", OCAMCALIB)
        stdout, _ = self.run_importer(path)
        cameras = image_reader_options(stdout)
        self.assertEqual(cameras["cam0"][0], "OCAM")
        # cx = yc + 0.5 (column), cy = xc + 0.5 (row); pol without a1.
        self.assert_params(cameras["cam0"][1],
                           [640.25, 479.75, 1.0005, 0.0002, -0.0001, -250,
                            0.0012, -1e-06, 2e-09])
        # COLMAP takes the OCAM camera as it is (id 66).
        images = self.path("images")
        os.makedirs(images)
        write_noise_image(os.path.join(images, "frame.pgm"), 1280, 960,
                          seed=3)
        database = self.path("database.db")
        run_colmap("feature_extractor", "--database_path", database,
                   "--image_path", images,
                   "--ImageReader.camera_model", "OCAM",
                   "--ImageReader.camera_params",
                   ",".join(repr(v) for v in cameras["cam0"][1]),
                   *CPU_EXTRACTION)
        db = Database(database)
        ((model, width, height, params),) = db.cameras().values()
        db.close()
        self.assertEqual((model, width, height), (66, 1280, 960))
        self.assert_params(params, cameras["cam0"][1])

        stdout, output = self.run_importer(path, "--camera_model",
                                           "OPENCV_FISHEYE")
        cameras = image_reader_options(stdout)
        self.assertEqual(cameras["cam0"][0], "OPENCV_FISHEYE")
        fit = re.search(r"fitted over (\d+) rays up to ([\d.]+) deg from the "
                        r"axis: median error ([\d.]+) px, max ([\d.]+) px",
                        stdout)
        self.assertIsNotNone(fit, stdout)
        self.assertGreater(int(fit.group(1)), 1000)
        self.assertGreater(float(fit.group(2)), 90)
        self.assertLess(float(fit.group(3)), 0.5)
        self.assertNotIn("not seen", stdout)
        self.assertAlmostEqual(cameras["cam0"][1][2], 640.25, delta=0.5)
        # The converted camera is one COLMAP takes.
        with open(os.path.join(output, "cameras.txt")) as f:
            line = [l for l in f if not l.startswith("#")][0].split()
        self.assertEqual(line[1:4], ["OPENCV_FISHEYE", "1280", "960"])

        # Given the lens's half field, the fit keeps to it.
        stdout, _ = self.run_importer(path, "--camera_model",
                                      "OPENCV_FISHEYE", "--half_field_deg",
                                      "80")
        fit = re.search(r"rays up to ([\d.]+) deg from the axis", stdout)
        self.assertIsNotNone(fit, stdout)
        self.assertLessEqual(float(fit.group(1)), 80)
        self.assertGreater(float(fit.group(1)), 78)

    def test_basalt(self):
        stdout, output = self.run_importer(
            self.write("calibration.json", json.dumps(BASALT, indent=1)))
        cameras = image_reader_options(stdout)
        self.assertEqual(cameras["cam0"][0], "OPENCV_FISHEYE")
        self.assert_params(cameras["cam0"][1],
                           [380, 381, 320, 240, 0.01, -0.002, 0.0004,
                            -0.00005])
        self.assertEqual(cameras["cam1"][0], "DOUBLE_SPHERE")
        with open(os.path.join(output, "rig_config.json")) as f:
            rig = json.load(f)[0]["cameras"]
        # cam1 = T_imu_cam1^-1 T_imu_cam0: a point of cam0 is at +0.01 in x
        # in the IMU; cam1 sits at -0.09 turned 90° about y (x1 = -z, z1 = x).
        point = (0.3, -0.2, 1.0)
        relative = (point[0] + 0.01 + 0.09, point[1], point[2])
        self.assert_params(self.in_camera(rig[1], point),
                           [-relative[2], relative[1], relative[0]])

    def test_bad_input_is_one_line_naming_file_and_field(self):
        fisheye_no_height = OPENCV_FISHEYE.replace("image_height: 960\n", "")
        basalt_missing = json.loads(json.dumps(BASALT))
        basalt_missing["value0"]["resolution"].pop()
        cases = [
            ("malformed.yaml", "cam0: [unclosed\n", ["--format", "kalibr"],
             "malformed.yaml: YAML: "),
            ("unknown.yaml", KALIBR.replace("camera_model: omni",
                                            "camera_model: scaramuzza"), [],
             "unknown.yaml: cam2.camera_model: unknown camera model"),
            ("gap.yaml", KALIBR.replace("cam2:", "cam3:"), [],
             "gap.yaml: cam2: missing"),
            ("nan.yaml", KALIBR.replace("458.654", ".nan"), [],
             "nan.yaml: cam0.intrinsics[0]: "),
            ("absurd.yaml", KALIBR.replace("[752, 480]", "[752, 0]"), [],
             "absurd.yaml: cam0.resolution[1]: "),
            ("noheight.yml", fisheye_no_height, [],
             "noheight.yml: image_height: missing"),
            ("calib_bad.txt", OCAMCALIB.replace("479.25 639.75", "479.25"),
             [], "calib_bad.txt: center: "),
            ("basalt_missing.json", json.dumps(basalt_missing), [],
             "basalt_missing.json: resolution: has 1 entries"),
            ("unknown_model.yaml", KALIBR, ["--camera_model", "FISHEYE9000"],
             "--camera_model: FISHEYE9000"),
            ("half_field.yaml", KALIBR, ["--half_field_deg", "200"],
             "--half_field_deg: 200 is not an angle"),
            ("anything.txt", "no calibration here\n", [],
             "anything.txt: format: "),
        ]
        for name, text, options, expected in cases:
            with self.subTest(name):
                path = self.write(name, text)
                output = self.path("out_bad")
                os.makedirs(output, exist_ok=True)
                before = listing(output)
                result = run_colmap("calibration_importer", "--input_path",
                                    path, "--output_path", output, *options,
                                    check=False)
                self.assertEqual(result.returncode, 1, result.stdout)
                errors = [line for line in result.stdout.splitlines()
                          if "calibration_importer: " in line]
                self.assertEqual(len(errors), 1, result.stdout)
                self.assertIn(expected, errors[0])
                self.assertEqual(listing(output), before)


if __name__ == "__main__":
    unittest.main()
