// `colmap calibration_importer --input_path FILE
//     [--format auto|kalibr|opencv|ocamcalib|basalt] [--camera_model NAME]
//     [--output_path DIR]`: another program's calibration (Kalibr camchain,
// OpenCV fisheye/omnidir file, OCamCalib calib_results.txt, Basalt JSON) as
// --ImageReader options per camera and, with --output_path, DIR/cameras.txt
// and for several cameras DIR/rig_config.json (calibration/calibration_io.h).
#pragma once

namespace colmap {

int RunCalibrationImporter(int argc, char** argv);

}  // namespace colmap
