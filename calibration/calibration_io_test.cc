#include "calibration/calibration_io.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "camera_models/registry.h"

namespace sphera {
namespace {

// A file with the given content in the test's temporary folder.
std::string WriteFile(const std::string& name, const std::string& text) {
  const std::filesystem::path path =
      std::filesystem::path(::testing::TempDir()) / name;
  std::ofstream(path) << text;
  return path.string();
}

ImportedCalibration Import(const std::string& name, const std::string& text,
                           const std::string& camera_model = "") {
  CalibrationImportOptions options;
  options.camera_model = camera_model;
  return ImportCalibrationFile(WriteFile(name, text), options);
}

void ExpectParams(const ImportedCamera& camera, const std::string& model,
                  const std::vector<double>& params) {
  EXPECT_EQ(camera.model_name, model);
  ASSERT_EQ(camera.params.size(), params.size());
  for (size_t i = 0; i < params.size(); ++i) {
    EXPECT_DOUBLE_EQ(camera.params[i], params[i]) << camera.name << " " << i;
  }
  EXPECT_FALSE(camera.fit.has_value());
}

// Where a point of the rig (cam0) frame lands in the camera's frame.
Eigen::Vector3d InCamera(const ImportedCamera& camera,
                         const Eigen::Vector3d& point_in_rig) {
  return *camera.cam_from_rig_rotation * point_in_rig +
         camera.cam_from_rig_translation;
}

// cam1 is cam0 turned 90° about y (cam1's z is cam0's -x) and 10 cm to the
// right; cam2 is cam1 turned 180° about y and moved 5 cm along cam1's z.
constexpr const char* kKalibrChain = R"(cam0:
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
cam3:
  T_cn_cnm1:
  - [1.0, 0.0, 0.0, 0.0]
  - [0.0, 1.0, 0.0, 0.0]
  - [0.0, 0.0, 1.0, 0.0]
  - [0.0, 0.0, 0.0, 1.0]
  camera_model: ds
  intrinsics: [-0.2, 0.6, 300.0, 300.0, 511.5, 511.5]
  distortion_model: none
  distortion_coeffs: []
  resolution: [1024, 1024]
cam4:
  T_cn_cnm1:
  - [1.0, 0.0, 0.0, 0.0]
  - [0.0, 1.0, 0.0, 0.0]
  - [0.0, 0.0, 1.0, 0.0]
  - [0.0, 0.0, 0.0, 1.0]
  camera_model: eucm
  intrinsics: [0.6, 1.1, 310.0, 311.0, 511.5, 511.5]
  distortion_model: none
  distortion_coeffs: []
  resolution: [1024, 1024]
)";

TEST(Kalibr, CamchainModelsAndChainedPoses) {
  const ImportedCalibration calibration = Import("camchain.yaml", kKalibrChain);
  EXPECT_EQ(calibration.format, CalibrationFormat::kKalibr);
  ASSERT_EQ(calibration.cameras.size(), 5u);
  const auto& cams = calibration.cameras;
  // Principal points gain half a pixel (COLMAP counts from the pixel corner).
  ExpectParams(cams[0], "OPENCV",
               {458.654, 457.296, 367.715, 248.875, -0.28340811, 0.07395907,
                0.00019359, 1.76187114e-05});
  ExpectParams(cams[1], "OPENCV_FISHEYE",
               {350, 351, 640, 480, 0.01, -0.002, 0.0003, -0.00004});
  ExpectParams(cams[2], "UNIFIED_OMNI",
               {700, 701, 512, 512, 1.2, -0.1, 0.02, 0.001, -0.002});
  ExpectParams(cams[3], "DOUBLE_SPHERE", {300, 300, 512, 512, -0.2, 0.6});
  ExpectParams(cams[4], "EUCM", {310, 311, 512, 512, 0.6, 1.1});
  EXPECT_EQ(cams[0].width, 752);
  EXPECT_EQ(cams[0].height, 480);
  EXPECT_EQ(cams[1].width, 1280);
  EXPECT_EQ(cams[0].source_model, "Kalibr pinhole-radtan");

  // cam0 is the rig.
  EXPECT_TRUE(cams[0].cam_from_rig_rotation->isApprox(
      Eigen::Quaterniond::Identity()));
  EXPECT_TRUE(cams[0].cam_from_rig_translation.isZero());
  // A point 1 m in front of cam0: cam1 (looking along cam0's -x, 10 cm
  // to cam0's right... T maps cam0 points: x1 = z0 + 0.1, z1 = -x0).
  const Eigen::Vector3d point(0.3, -0.2, 1.0);
  EXPECT_TRUE(InCamera(cams[1], point).isApprox(Eigen::Vector3d(1.1, -0.2, -0.3),
                                               1e-12));
  // cam2 = T21 T10: x2 = -x1, z2 = -z1 + 0.05.
  EXPECT_TRUE(InCamera(cams[2], point).isApprox(
      Eigen::Vector3d(-1.1, -0.2, 0.35), 1e-12));
  EXPECT_TRUE(InCamera(cams[4], point).isApprox(InCamera(cams[2], point), 1e-12));
}

TEST(Kalibr, PinholeFovIsFittedAndReportsItsError) {
  const ImportedCalibration calibration = Import("fov.yaml", R"(cam0:
  camera_model: pinhole
  intrinsics: [400.0, 400.0, 375.5, 239.5]
  distortion_model: fov
  distortion_coeffs: [0.9]
  resolution: [752, 480]
)");
  ASSERT_EQ(calibration.cameras.size(), 1u);
  const ImportedCamera& camera = calibration.cameras[0];
  EXPECT_EQ(camera.source_model, "Kalibr pinhole-fov");
  ASSERT_TRUE(camera.fit.has_value());
  EXPECT_GT(camera.fit->num_samples, 100);
  EXPECT_LT(camera.fit->max_error_px, 0.5);
  EXPECT_NEAR(camera.params[2], 376, 0.05);
  EXPECT_NEAR(camera.params[3], 240, 0.05);
  EXPECT_FALSE(camera.cam_from_rig_rotation.has_value());
}

TEST(Kalibr, ConvertsToTheModelAskedFor) {
  const ImportedCalibration calibration =
      Import("camchain_ds.yaml", R"(cam0:
  camera_model: ds
  intrinsics: [-0.2, 0.6, 300.0, 300.0, 511.5, 511.5]
  distortion_model: none
  distortion_coeffs: []
  resolution: [1024, 1024]
)", "UNIFIED_OMNI");
  const ImportedCamera& camera = calibration.cameras[0];
  EXPECT_EQ(camera.model_name, "UNIFIED_OMNI");
  ASSERT_TRUE(camera.fit.has_value());
  EXPECT_LT(camera.fit->max_error_px, 1.0);
  EXPECT_EQ(camera.fit->num_not_visible, 0);
}

constexpr const char* kOpenCVFisheyeYaml = R"(%YAML:1.0
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
)";

TEST(OpenCV, FisheyeYaml) {
  const ImportedCalibration calibration =
      Import("fisheye.yml", kOpenCVFisheyeYaml);
  EXPECT_EQ(calibration.format, CalibrationFormat::kOpenCV);
  ASSERT_EQ(calibration.cameras.size(), 1u);
  ExpectParams(calibration.cameras[0], "OPENCV_FISHEYE",
               {330.5, 331.5, 640, 480, 0.021, -0.0051, 0.0009, -0.0001});
  EXPECT_TRUE(calibration.notes.empty());
}

// A 200-degree circular fisheye: the Kannala-Brandt shape of the realistic
// rigs, its image circle (radius 491.5 px at 100 degrees) inside a
// 1024 x 1024 frame whose corners the polynomial maps to 156 degrees.
constexpr char kCircularFisheyeYaml[] = R"(%YAML:1.0
---
image_width: 1024
image_height: 1024
fisheye_model: 1
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 289.54, 0., 512., 0., 289.54, 512., 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 4
   cols: 1
   dt: d
   data: [ -0.012, 0.0016, -0.0002, 0. ]
)";

TEST(OpenCV, AFitKeepsToTheHalfFieldItIsGiven) {
  CalibrationImportOptions options;
  options.camera_model = "DOUBLE_SPHERE";
  const std::string path = WriteFile("circular.yml", kCircularFisheyeYaml);
  const ImportedCamera whole_frame =
      ImportCalibrationFile(path, options).cameras[0];
  options.half_field_deg = 100;
  const ImportedCamera circle = ImportCalibrationFile(path, options).cameras[0];
  ASSERT_TRUE(whole_frame.fit.has_value());
  ASSERT_TRUE(circle.fit.has_value());
  EXPECT_GT(whole_frame.fit->max_angle_deg, 150);
  EXPECT_LE(circle.fit->max_angle_deg, 100);
  EXPECT_GT(circle.fit->max_angle_deg, 99);
  // Fitted where the lens images, DOUBLE_SPHERE follows it within a few
  // tenths of a pixel; pulled towards the black corners it does not.
  EXPECT_LT(circle.fit->max_error_px, 0.5);
  EXPECT_GT(whole_frame.fit->max_error_px, 1.0);

  options.half_field_deg = 200;
  EXPECT_THROW(ImportCalibrationFile(path, options), std::invalid_argument);
}

TEST(OpenCV, OmnidirXml) {
  const ImportedCalibration calibration = Import("omni.xml", R"(<?xml version="1.0"?>
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
)");
  ASSERT_EQ(calibration.cameras.size(), 1u);
  ExpectParams(calibration.cameras[0], "UNIFIED_OMNI",
               {600, 601, 512, 384, 1.1, -0.2, 0.05, 0.001, 0.0005});
  EXPECT_EQ(calibration.cameras[0].source_model, "OpenCV omnidir");
}

TEST(OpenCV, FourCoefficientsWithoutAModelAreFisheyeWithANote) {
  std::string text = kOpenCVFisheyeYaml;
  text.erase(text.find("fisheye_model: 1\n"), 17);
  const ImportedCalibration calibration = Import("plain4.yml", text);
  EXPECT_EQ(calibration.cameras[0].model_name, "OPENCV_FISHEYE");
  ASSERT_EQ(calibration.notes.size(), 1u);
  EXPECT_NE(calibration.notes[0].find("cv::fisheye"), std::string::npos);

  std::string pinhole = text;
  pinhole.insert(pinhole.find("image_width"), "model: pinhole\n");
  EXPECT_EQ(Import("pinhole4.yml", pinhole).cameras[0].model_name, "OPENCV");
}

TEST(OpenCV, PinholeWithK3IsFittedToOpenCV) {
  const ImportedCalibration calibration = Import("pinhole.yml", R"(%YAML:1.0
---
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 500., 0., 319.5, 0., 500., 239.5, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -0.1, 0.02, 0., 0., 0.001 ]
)");
  const ImportedCamera& camera = calibration.cameras[0];
  ASSERT_TRUE(camera.fit.has_value());
  EXPECT_EQ(camera.fit->num_not_visible, 0);
  EXPECT_LT(camera.fit->max_error_px, 0.5);
  EXPECT_EQ(camera.source_model, "OpenCV pinhole");
}

constexpr const char* kOCamCalibResults =
    R"(#polynomial coefficients for the DIRECT mapping function (ocam_model.ss in MATLAB). These are used by cam2world

5 -2.500000e+02 0.000000e+00 1.200000e-03 -1.000000e-06 2.000000e-09 

#polynomial coefficients for the inverse mapping function (ocam_model.invpol in MATLAB). These are used by world2cam

3 250.0 100.0 10.0 

#center: "row" and "column", starting from 0 (C convention)

479.25 639.75

#affine parameters "c", "d", "e"

1.000500 0.000200 -0.000100

#image size: "height" and "width"

960 1280
)";

TEST(OCamCalib, CalibResultsCarryOverWithSwappedCentre) {
  const ImportedCalibration calibration =
      Import("calib_results.txt", kOCamCalibResults);
  EXPECT_EQ(calibration.format, CalibrationFormat::kOCamCalib);
  ASSERT_EQ(calibration.cameras.size(), 1u);
  const ImportedCamera& camera = calibration.cameras[0];
  EXPECT_EQ(camera.width, 1280);
  EXPECT_EQ(camera.height, 960);
  // cx = yc + 0.5 (column), cy = xc + 0.5 (row).
  ExpectParams(camera, "OCAM",
               {640.25, 479.75, 1.0005, 0.0002, -0.0001, -250, 0.0012, -1e-06,
                2e-09});
}

TEST(OCamCalib, ConvertsToOpenCVFisheyeForTheMapper) {
  const ImportedCalibration calibration =
      Import("calib_results.txt", kOCamCalibResults, "OPENCV_FISHEYE");
  const ImportedCamera& camera = calibration.cameras[0];
  EXPECT_EQ(camera.model_name, "OPENCV_FISHEYE");
  ASSERT_TRUE(camera.fit.has_value());
  EXPECT_EQ(camera.fit->num_not_visible, 0);
  EXPECT_LT(camera.fit->median_error_px, 0.5);
  EXPECT_GT(camera.fit->max_angle_deg, 90);
  // The ray of the OCAM centre is the fitted model's principal point.
  EXPECT_NEAR(camera.params[2], 640.25, 0.5);
  EXPECT_NEAR(camera.params[3], 479.75, 0.5);
}

TEST(OCamCalib, APolynomialOfHigherDegreeIsFitted) {
  std::string text = kOCamCalibResults;
  const std::string pol = "5 -2.500000e+02 0.000000e+00 1.200000e-03 -1.000000e-06 2.000000e-09";
  text.replace(text.find(pol), pol.size(),
               "6 -2.500000e+02 0.000000e+00 1.200000e-03 -1.000000e-06 "
               "2.000000e-09 1.0e-13");
  const ImportedCalibration calibration = Import("calib_results6.txt", text);
  const ImportedCamera& camera = calibration.cameras[0];
  ASSERT_TRUE(camera.fit.has_value());
  EXPECT_EQ(camera.source_model, "OCamCalib polynomial of degree 5");
  EXPECT_LT(camera.fit->median_error_px, 1.0);
}

constexpr const char* kBasalt = R"({
  "value0": {
    "T_imu_cam": [
      {"px": 0.01, "py": 0.0, "pz": 0.0,
       "qx": 0.0, "qy": 0.0, "qz": 0.0, "qw": 1.0},
      {"px": -0.09, "py": 0.0, "pz": 0.0,
       "qx": 0.0, "qy": 0.7071067811865476, "qz": 0.0, "qw": 0.7071067811865476}
    ],
    "intrinsics": [
      {"camera_type": "kb4",
       "intrinsics": {"fx": 380.0, "fy": 381.0, "cx": 319.5, "cy": 239.5,
                      "k1": 0.01, "k2": -0.002, "k3": 0.0004, "k4": -0.00005}},
      {"camera_type": "ds",
       "intrinsics": {"fx": 300.0, "fy": 300.0, "cx": 319.5, "cy": 239.5,
                      "xi": -0.2, "alpha": 0.6}}
    ],
    "resolution": [[640, 480], [640, 480]],
    "vignette": [],
    "calib_accel_bias": [0, 0, 0, 0, 0, 0, 0, 0, 0],
    "calib_gyro_bias": [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]
  }
}
)";

TEST(Basalt, CamerasAndPosesFromTImuCam) {
  const ImportedCalibration calibration = Import("calibration.json", kBasalt);
  EXPECT_EQ(calibration.format, CalibrationFormat::kBasalt);
  ASSERT_EQ(calibration.cameras.size(), 2u);
  ExpectParams(calibration.cameras[0], "OPENCV_FISHEYE",
               {380, 381, 320, 240, 0.01, -0.002, 0.0004, -0.00005});
  ExpectParams(calibration.cameras[1], "DOUBLE_SPHERE",
               {300, 300, 320, 240, -0.2, 0.6});
  // cam1 = imu_from_cam1^-1 imu_from_cam0: a point of cam0 goes to the IMU
  // (+0.01 in x), then into cam1 (R = 90° about y: x1 = -z_i, z1 = x_i, at
  // -0.09 in x).
  const Eigen::Vector3d point(0.3, -0.2, 1.0);
  const Eigen::Vector3d in_imu = point + Eigen::Vector3d(0.01, 0, 0);
  const Eigen::Vector3d relative = in_imu - Eigen::Vector3d(-0.09, 0, 0);
  const Eigen::Vector3d expected(-relative.z(), relative.y(), relative.x());
  EXPECT_TRUE(InCamera(calibration.cameras[1], point).isApprox(expected, 1e-12))
      << InCamera(calibration.cameras[1], point).transpose();
  EXPECT_TRUE(InCamera(calibration.cameras[0], point).isApprox(point, 1e-12));
}

TEST(Basalt, UcmIsUnifiedOmniExactly) {
  std::string text = kBasalt;
  const std::string ds = R"("camera_type": "ds",
       "intrinsics": {"fx": 300.0, "fy": 300.0, "cx": 319.5, "cy": 239.5,
                      "xi": -0.2, "alpha": 0.6})";
  text.replace(text.find(ds), ds.size(), R"("camera_type": "ucm",
       "intrinsics": {"fx": 300.0, "fy": 310.0, "cx": 319.5, "cy": 239.5,
                      "alpha": 0.6})");
  const ImportedCamera camera = Import("ucm.json", text).cameras[1];
  EXPECT_EQ(camera.model_name, "UNIFIED_OMNI");
  // Basalt's UCM: u = fx x / (alpha d + (1 - alpha) z) + cx.
  for (const Eigen::Vector3d& ray :
       {Eigen::Vector3d(0.3, -0.2, 1.0), Eigen::Vector3d(1.0, 0.5, -0.3)}) {
    const double denominator = 0.6 * ray.norm() + 0.4 * ray.z();
    const Eigen::Vector2d expected(300 * ray.x() / denominator + 320,
                                   310 * ray.y() / denominator + 240);
    Eigen::Vector2d pixel;
    ASSERT_TRUE(ImageFromRay(camera.model_id, camera.params, ray, &pixel));
    EXPECT_TRUE(pixel.isApprox(expected, 1e-12)) << pixel.transpose();
  }
}

TEST(Output, RigConfigAndCamerasText) {
  const ImportedCalibration calibration = Import("camchain.yaml", kKalibrChain);
  const std::string config = RigConfigJson(calibration);
  EXPECT_NE(config.find("\"image_prefix\": \"cam0/\",\n        \"ref_sensor\": true"),
            std::string::npos)
      << config;
  EXPECT_NE(config.find("\"image_prefix\": \"cam1/\""), std::string::npos);
  // cam1's rotation: 90° about -y... (w, x, y, z) of R = [0 0 1; 0 1 0; -1 0 0]
  // is (cos 45°, 0, sin 45°, 0).
  const size_t rotation = config.find("\"cam_from_rig_rotation\": [");
  ASSERT_NE(rotation, std::string::npos) << config;
  double w, x, y, z;
  ASSERT_EQ(std::sscanf(config.c_str() + rotation,
                        "\"cam_from_rig_rotation\": [%lf, %lf, %lf, %lf]", &w,
                        &x, &y, &z),
            4);
  EXPECT_NEAR(w, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(x, 0, 1e-15);
  EXPECT_NEAR(y, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(z, 0, 1e-15);
  EXPECT_NE(config.find("\"cam_from_rig_translation\": [0.1, 0, 0]"),
            std::string::npos);
  EXPECT_NE(config.find("\"camera_model_name\": \"DOUBLE_SPHERE\",\n        "
                        "\"camera_params\": [300, 300, 512, 512, -0.2, 0.6]"),
            std::string::npos);
  const std::string cameras = CamerasText(calibration);
  EXPECT_NE(cameras.find("\n4 DOUBLE_SPHERE 1024 1024 300 300 512 512 -0.2 0.6\n"),
            std::string::npos)
      << cameras;
  EXPECT_EQ(ImageReaderOptions(calibration.cameras[3]),
            "--ImageReader.camera_model DOUBLE_SPHERE "
            "--ImageReader.camera_params 300,300,512,512,-0.2,0.6");
}

TEST(Format, DetectedFromContent) {
  EXPECT_EQ(DetectCalibrationFormat(kKalibrChain), CalibrationFormat::kKalibr);
  EXPECT_EQ(DetectCalibrationFormat(kOpenCVFisheyeYaml),
            CalibrationFormat::kOpenCV);
  EXPECT_EQ(DetectCalibrationFormat(kOCamCalibResults),
            CalibrationFormat::kOCamCalib);
  EXPECT_EQ(DetectCalibrationFormat(kBasalt), CalibrationFormat::kBasalt);
  EXPECT_EQ(DetectCalibrationFormat("hello"), CalibrationFormat::kAuto);
  EXPECT_EQ(CalibrationFormatFromName("Kalibr"), CalibrationFormat::kKalibr);
  EXPECT_THROW(CalibrationFormatFromName("colmap"), std::invalid_argument);
}

// -- bad input: one line naming the file and the field ------------------------

// The message of the error importing TEXT as FILE_NAME.
std::string ErrorOf(const std::string& file_name, const std::string& text,
                    CalibrationFormat format = CalibrationFormat::kAuto) {
  CalibrationImportOptions options;
  options.format = format;
  try {
    ImportCalibrationText(text, file_name, options);
  } catch (const CalibrationError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(file_name + ": ", 0), 0u) << message;
    return message;
  }
  ADD_FAILURE() << "no error for " << file_name;
  return "";
}

std::string Replaced(std::string text, const std::string& from,
                     const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

void ExpectContains(const std::string& message, const std::string& part) {
  EXPECT_NE(message.find(part), std::string::npos)
      << "\"" << message << "\" lacks \"" << part << "\"";
}

TEST(BadInput, Kalibr) {
  ExpectContains(ErrorOf("a.yaml", "cam0: [unclosed", CalibrationFormat::kKalibr),
                 "a.yaml: YAML: ");
  ExpectContains(ErrorOf("b.yaml", Replaced(kKalibrChain, "camera_model: ds",
                                            "camera_model: scaramuzza")),
                 "b.yaml: cam3.camera_model: unknown camera model \"scaramuzza\"");
  ExpectContains(ErrorOf("c.yaml", Replaced(kKalibrChain, "cam2:", "cam7:")),
                 "c.yaml: cam2: missing");
  ExpectContains(
      ErrorOf("d.yaml",
              Replaced(kKalibrChain,
                       "cam1:\n  T_cn_cnm1:\n  - [0.0, 0.0, 1.0, 0.1]\n  - "
                       "[0.0, 1.0, 0.0, 0.0]\n  - [-1.0, 0.0, 0.0, 0.0]\n  - "
                       "[0.0, 0.0, 0.0, 1.0]\n",
                       "cam1:\n")),
      "d.yaml: cam1.T_cn_cnm1: missing");
  ExpectContains(ErrorOf("e.yaml", Replaced(kKalibrChain, "458.654", ".nan")),
                 "e.yaml: cam0.intrinsics[0]: ");
  ExpectContains(ErrorOf("f.yaml", Replaced(kKalibrChain, "458.654", "-458")),
                 "f.yaml: cam0.intrinsics fx: focal length -458");
  ExpectContains(ErrorOf("g.yaml", Replaced(kKalibrChain, "[752, 480]",
                                            "[752.5, 480]")),
                 "g.yaml: cam0.resolution[0]");
  ExpectContains(ErrorOf("h.yaml", Replaced(kKalibrChain, "[0.0, 0.0, 1.0, 0.1]",
                                            "[0.0, 0.5, 1.0, 0.1]")),
                 "h.yaml: cam1.T_cn_cnm1: the 3x3 block is not a rotation");
  ExpectContains(ErrorOf("i.yaml", Replaced(kKalibrChain, "distortion_model: equidistant",
                                            "distortion_model: rational")),
                 "i.yaml: cam1.distortion_model: unknown distortion model");
  ExpectContains(ErrorOf("j.yaml", Replaced(kKalibrChain, "[1.2, 700.0, 701.0, 511.5, 511.5]",
                                            "[700.0, 701.0, 511.5, 511.5]")),
                 "j.yaml: cam2.intrinsics: must be a list of 5 numbers");
  ExpectContains(ErrorOf("k.yaml", Replaced(kKalibrChain, "[0.0, 0.0, -1.0, 0.05]",
                                            "[0.0, 0.0, -1.0, 1e9]")),
                 "k.yaml: cam2.T_cn_cnm1: translation");
}

TEST(BadInput, OpenCV) {
  ExpectContains(ErrorOf("a.yml", "%YAML:1.0\n---\nimage_width: [1, 2\n",
                         CalibrationFormat::kOpenCV),
                 "a.yml: FileStorage: ");
  ExpectContains(ErrorOf("b.yml", Replaced(kOpenCVFisheyeYaml, "image_height: 960\n", "")),
                 "b.yml: image_height: missing");
  ExpectContains(ErrorOf("c.yml", Replaced(kOpenCVFisheyeYaml, "camera_matrix", "camera_matrx")),
                 "c.yml: camera_matrix: missing");
  ExpectContains(ErrorOf("d.yml", Replaced(kOpenCVFisheyeYaml, "0.021", ".nan")),
                 "d.yml: distortion_coefficients[0]");
  ExpectContains(ErrorOf("e.yml", Replaced(kOpenCVFisheyeYaml, "fisheye_model: 1",
                                           "model: division")),
                 "e.yml: model: unknown model \"division\"");
  ExpectContains(ErrorOf("f.yml", Replaced(kOpenCVFisheyeYaml, "330.5, 0., 639.5",
                                           "330.5, 0., 1e7")),
                 "f.yml: camera_matrix cx");
  ExpectContains(
      ErrorOf("g.yml", Replaced(kOpenCVFisheyeYaml,
                                "rows: 4\n   cols: 1\n   dt: d\n   data: [ "
                                "0.021, -0.0051, 0.0009, -0.0001 ]",
                                "rows: 3\n   cols: 1\n   dt: d\n   data: [ "
                                "0.021, -0.0051, 0.0009 ]")),
      "g.yml: distortion_coefficients: cv::fisheye needs 4");
  ExpectContains(ErrorOf("h.yml", Replaced(kOpenCVFisheyeYaml, "0.0009, -0.0001 ]",
                                           "0.0009 ]")),
                 "h.yml: distortion_coefficients: is not a valid matrix");
}

TEST(BadInput, OCamCalib) {
  const std::string pol =
      "5 -2.500000e+02 0.000000e+00 1.200000e-03 -1.000000e-06 2.000000e-09";
  ExpectContains(ErrorOf("a.txt", Replaced(kOCamCalibResults, "960 1280", "")),
                 "a.txt: image size: missing");
  ExpectContains(ErrorOf("b.txt", Replaced(kOCamCalibResults, pol, "7 -250 0 1e-3")),
                 "b.txt: polynomial coefficients: must be a count N");
  ExpectContains(ErrorOf("c.txt", Replaced(kOCamCalibResults, "479.25 639.75", "479.25 nan")),
                 "c.txt: center[1]");
  ExpectContains(ErrorOf("d.txt", Replaced(kOCamCalibResults, "-2.500000e+02", "2.5e2")),
                 "d.txt: polynomial coefficients: a0 = 250 must be negative");
  ExpectContains(ErrorOf("e.txt", Replaced(kOCamCalibResults, "1.000500 0.000200", "1.000500 abc")),
                 "e.txt: affine parameters: \"abc\" is not a number");
  // A polynomial that folds inside the image: OCAM's own check names it.
  ExpectContains(ErrorOf("f.txt", Replaced(kOCamCalibResults, pol,
                                           "5 -250 0 1.2e-3 -1e-5 0")),
                 "f.txt: cam0: OCAM");
}

TEST(BadInput, Basalt) {
  ExpectContains(ErrorOf("a.json", "{\"value0\": {", CalibrationFormat::kBasalt),
                 "a.json: JSON: ");
  ExpectContains(ErrorOf("b.json", Replaced(kBasalt, "\"kb4\"", "\"bal\"")),
                 "b.json: intrinsics[0].camera_type: unknown camera type \"bal\"");
  ExpectContains(ErrorOf("c.json", Replaced(kBasalt, "[[640, 480], [640, 480]]",
                                            "[[640, 480]]")),
                 "c.json: resolution: has 1 entries");
  ExpectContains(ErrorOf("d.json", Replaced(kBasalt, "\"xi\": -0.2", "\"xi\": \"x\"")),
                 "d.json: intrinsics[1].intrinsics.xi: is not a number");
  ExpectContains(ErrorOf("e.json", Replaced(kBasalt, "\"qw\": 1.0", "\"qw\": 2.0")),
                 "e.json: T_imu_cam[0]: quaternion of norm 2");
  ExpectContains(ErrorOf("f.json", Replaced(kBasalt, "\"fx\": 380.0", "\"fx\": 1e300")),
                 "f.json: intrinsics[0].intrinsics fx: focal length");
  ExpectContains(ErrorOf("g.json", Replaced(kBasalt, "\"alpha\": 0.6}", "\"alpha\": 1.5}")),
                 "g.json: cam1: DOUBLE_SPHERE: alpha=1.5");
}

TEST(BadInput, UnknownFormatAndModel) {
  ExpectContains(ErrorOf("x.txt", "just some text"), "x.txt: format: ");
  CalibrationImportOptions options;
  options.camera_model = "FISHEYE_9000";
  EXPECT_THROW(ImportCalibrationText(kBasalt, "calibration.json", options),
               std::invalid_argument);
  options.camera_model = "EQUIRECTANGULAR";
  EXPECT_THROW(ImportCalibrationText(kBasalt, "calibration.json", options),
               std::invalid_argument);
  EXPECT_THROW(ImportCalibrationFile("/nonexistent/calib.yaml",
                                     CalibrationImportOptions()),
               CalibrationError);
}

}  // namespace
}  // namespace sphera
