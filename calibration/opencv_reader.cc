// OpenCV calibration files (cv::FileStorage, YAML with a "%YAML:1.0" header,
// XML or JSON) as OpenCV's calibration samples and most programs write them:
//   camera_matrix | K | cameraMatrix | intrinsic_matrix   3x3 [fx s cx; 0 fy cy; 0 0 1]
//   distortion_coefficients | D | dist_coeffs | distCoeffs | distortion_coeffs
//   xi                                 cv::omnidir's mirror parameter
//   image_width | width | imageWidth, image_height | height | imageHeight,
//   or image_size | imageSize | resolution = [width, height]
//   fisheye_model (0 / 1, the calibration sample's flag) or
//   model | camera_model | distortion_model = fisheye | omnidir | pinhole
// The lens: cv::omnidir when xi is given (D = k1, k2, p1, p2; UNIFIED_OMNI,
// fitted when K has a skew); cv::fisheye when the flag or model says so, or
// when D has exactly 4 coefficients and nothing says otherwise (noted);
// else cv::calibrateCamera's pinhole with 4 to 12 coefficients (OPENCV, fitted
// when k3.. are not zero). Pixels count from the centre of the first pixel.
#include <initializer_list>

#include <opencv2/core.hpp>
#include <opencv2/core/persistence.hpp>

#include "calibration/calibration_readers.h"

namespace sphera {
namespace calibration_internal {
namespace {

// The first of the names the file has, or an empty node; *found gets the name.
cv::FileNode FirstOf(const cv::FileStorage& storage,
                     std::initializer_list<const char*> names,
                     std::string* found) {
  for (const char* name : names) {
    cv::FileNode node = storage[name];
    if (!node.empty() && !node.isNone()) {
      *found = name;
      return node;
    }
  }
  return cv::FileNode();
}

// The numbers of a matrix node (opencv-matrix) or of a list.
std::vector<double> Numbers(const std::string& file, const std::string& field,
                            const cv::FileNode& node) {
  std::vector<double> values;
  if (node.isReal() || node.isInt()) {
    values.push_back(static_cast<double>(node));
  } else if (node.isSeq()) {
    for (const cv::FileNode& item : node) {
      if (!item.isReal() && !item.isInt()) {
        throw CalibrationError(file, field, "has an entry that is not a number");
      }
      values.push_back(static_cast<double>(item));
    }
  } else if (node.isMap()) {
    // An opencv-matrix, read here: cv::Mat would allocate rows x cols as the
    // file states them before it reads the data.
    const cv::FileNode rows = node["rows"];
    const cv::FileNode cols = node["cols"];
    const cv::FileNode data = node["data"];
    if (!rows.isInt() || !cols.isInt() ||
        !(data.isSeq() || data.isReal() || data.isInt())) {
      throw CalibrationError(file, field,
                             "is not a matrix (rows, cols and data)");
    }
    const int num_rows = static_cast<int>(rows);
    const int num_cols = static_cast<int>(cols);
    // XML holds a 1x1 matrix's data as one number.
    const size_t num_values = data.isSeq() ? data.size() : 1;
    if (num_rows < 1 || num_rows > 16 || num_cols < 1 || num_cols > 16 ||
        num_values != static_cast<size_t>(num_rows * num_cols)) {
      throw CalibrationError(file, field,
                             "is not a valid matrix: " +
                                 std::to_string(num_values) +
                                 " data values for " +
                                 std::to_string(num_rows) + "x" +
                                 std::to_string(num_cols));
    }
    values = Numbers(file, field, data);
  } else {
    throw CalibrationError(file, field, "is not a number, list or matrix");
  }
  for (size_t i = 0; i < values.size(); ++i) {
    FiniteNumber(file, field + "[" + std::to_string(i) + "]", values[i]);
  }
  return values;
}

std::string Lowercase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

ParsedFile ReadStorage(const cv::FileStorage& storage, const std::string& file) {
  ParsedFile parsed;
  std::string name;

  // Image size.
  int width = 0, height = 0;
  const cv::FileNode size_node =
      FirstOf(storage, {"image_size", "imageSize", "resolution"}, &name);
  if (!size_node.empty()) {
    const std::vector<double> size = Numbers(file, name, size_node);
    if (size.size() != 2) {
      throw CalibrationError(file, name, "must be [width, height]");
    }
    width = ImageSide(file, name + "[0]", size[0]);
    height = ImageSide(file, name + "[1]", size[1]);
  } else {
    const cv::FileNode width_node =
        FirstOf(storage, {"image_width", "width", "imageWidth"}, &name);
    if (width_node.empty()) {
      throw CalibrationError(file, "image_width",
                             "missing (or image_size: [width, height])");
    }
    std::vector<double> value = Numbers(file, name, width_node);
    if (value.size() != 1) throw CalibrationError(file, name, "is not a number");
    width = ImageSide(file, name, value[0]);
    const cv::FileNode height_node =
        FirstOf(storage, {"image_height", "height", "imageHeight"}, &name);
    if (height_node.empty()) {
      throw CalibrationError(file, "image_height", "missing");
    }
    value = Numbers(file, name, height_node);
    if (value.size() != 1) throw CalibrationError(file, name, "is not a number");
    height = ImageSide(file, name, value[0]);
  }

  // K.
  const cv::FileNode k_node = FirstOf(
      storage, {"camera_matrix", "K", "cameraMatrix", "intrinsic_matrix"},
      &name);
  if (k_node.empty()) {
    throw CalibrationError(file, "camera_matrix", "missing (or K)");
  }
  const std::string k_field = name;
  const std::vector<double> k = Numbers(file, k_field, k_node);
  if (k.size() != 9) {
    throw CalibrationError(file, k_field, "must be a 3x3 matrix");
  }
  if (k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1) {
    throw CalibrationError(file, k_field,
                           "is not [fx s cx; 0 fy cy; 0 0 1]");
  }
  GenericLens lens;
  lens.fx = k[0];
  lens.skew = k[1];
  lens.cx = k[2] + 0.5;
  lens.fy = k[4];
  lens.cy = k[5] + 0.5;
  CheckPinhole(file, k_field, lens.fx, lens.fy, lens.cx, lens.cy, width,
               height);
  if (std::abs(lens.skew) > lens.fx) {
    throw CalibrationError(file, k_field,
                           "skew " + FormatDouble(lens.skew) +
                               " is larger than the focal length");
  }

  // D.
  const cv::FileNode d_node = FirstOf(
      storage,
      {"distortion_coefficients", "D", "dist_coeffs", "distCoeffs",
       "distortion_coeffs"},
      &name);
  const std::string d_field = d_node.empty() ? "distortion_coefficients" : name;
  std::vector<double> d;
  if (!d_node.empty()) d = Numbers(file, d_field, d_node);

  // The lens type.
  std::string model;
  const cv::FileNode flag_node = storage["fisheye_model"];
  if (!flag_node.empty() && !flag_node.isNone()) {
    const std::vector<double> flag = Numbers(file, "fisheye_model", flag_node);
    if (flag.size() == 1 && flag[0] != 0) model = "fisheye";
  }
  const cv::FileNode model_node =
      FirstOf(storage, {"model", "camera_model", "distortion_model"}, &name);
  if (!model_node.empty()) {
    if (!model_node.isString()) {
      throw CalibrationError(file, name, "is not a model name");
    }
    model = Lowercase(static_cast<std::string>(model_node));
    if (model == "equidistant" || model == "kannala_brandt") model = "fisheye";
    if (model == "omni" || model == "mei") model = "omnidir";
    if (model == "radtan" || model == "plumb_bob") model = "pinhole";
    if (model != "fisheye" && model != "omnidir" && model != "pinhole") {
      throw CalibrationError(file, name,
                             "unknown model \"" + model +
                                 "\" (fisheye, omnidir, pinhole)");
    }
  }
  const cv::FileNode xi_node = storage["xi"];
  if (!xi_node.empty() && !xi_node.isNone()) {
    if (!model.empty() && model != "omnidir") {
      throw CalibrationError(file, "xi",
                             "is given but the model is " + model);
    }
    model = "omnidir";
    const std::vector<double> xi = Numbers(file, "xi", xi_node);
    if (xi.size() != 1) throw CalibrationError(file, "xi", "is not a number");
    if (xi[0] < 0 || xi[0] > 100) {
      throw CalibrationError(file, "xi",
                             FormatDouble(xi[0]) + " is not in [0, 100]");
    }
    lens.projection = LensProjection::kUnified;
    lens.projection_params = xi;
  } else if (model == "omnidir") {
    throw CalibrationError(file, "xi", "missing (cv::omnidir's xi)");
  }
  if (model.empty()) {
    if (d.size() == 4) {
      model = "fisheye";
      parsed.notes.push_back(
          d_field + " has 4 coefficients and nothing names the model: read "
          "as cv::fisheye's k1..k4 (add \"model: pinhole\" for a pinhole's "
          "k1, k2, p1, p2)");
    } else {
      model = "pinhole";
    }
  }

  if (model == "fisheye") {
    if (d.size() != 4) {
      throw CalibrationError(file, d_field,
                             "cv::fisheye needs 4 coefficients k1..k4, got " +
                                 std::to_string(d.size()));
    }
    lens.distortion = LensDistortion::kEquidistant;
  } else if (model == "omnidir") {
    if (d.size() != 4 && !d.empty()) {
      throw CalibrationError(file, d_field,
                             "cv::omnidir needs 4 coefficients k1, k2, p1, "
                             "p2, got " + std::to_string(d.size()));
    }
    lens.distortion = LensDistortion::kRadTan;
  } else {
    if (!(d.empty() || d.size() == 4 || d.size() == 5 || d.size() == 8 ||
          d.size() == 12 || d.size() == 14)) {
      throw CalibrationError(file, d_field,
                             "a pinhole's distortion has 4, 5, 8, 12 or 14 "
                             "coefficients, got " + std::to_string(d.size()));
    }
    if (d.size() == 14 && (d[12] != 0 || d[13] != 0)) {
      throw CalibrationError(file, d_field,
                             "a tilted sensor (tauX, tauY) is not supported");
    }
    if (d.size() == 14) d.resize(12);
    lens.distortion = LensDistortion::kRational;
  }
  lens.distortion_coeffs = d;
  const std::string source =
      model == "omnidir" ? "OpenCV omnidir"
                         : (model == "fisheye" ? "OpenCV fisheye"
                                               : "OpenCV pinhole");
  parsed.cameras.push_back(LensCamera("cam0", source, width, height, lens));
  return parsed;
}

}  // namespace

ParsedFile ReadOpenCV(const std::string& text, const std::string& file) {
  try {
    cv::FileStorage storage(text,
                            cv::FileStorage::READ | cv::FileStorage::MEMORY);
    if (!storage.isOpened()) {
      throw CalibrationError(file, "FileStorage",
                             "not a YAML, XML or JSON file of OpenCV");
    }
    return ReadStorage(storage, file);
  } catch (const CalibrationError&) {
    throw;
  } catch (const cv::Exception& error) {
    throw CalibrationError(file, "FileStorage", error.err);
  } catch (const std::exception& error) {
    // OpenCV's parsers also let std::length_error and the like through.
    throw CalibrationError(file, "FileStorage", error.what());
  }
}

}  // namespace calibration_internal
}  // namespace sphera
