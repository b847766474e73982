#include "colmap_ext/exe/dual_fisheye_splitter.h"

#include "colmap/controllers/option_manager.h"
#include "colmap/sensor/models.h"
#include "colmap/util/logging.h"
#include "colmap_ext/image/dual_fisheye_split.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <unistd.h>

namespace colmap {
namespace {

namespace fs = std::filesystem;

struct DualFisheyeSplitterOptions {
  fs::path input_path;
  fs::path output_path;
  fs::path image_list_path;
  std::string lens_names = "lens0,lens1";
  std::string circles;
  int black_level = 10;
  std::string camera_model;
  std::string camera_params;
  int jpeg_quality = 95;
};

// File name extensions (lower case) of the raw frames looked for in
// --input_path; other files are left alone. Insta360's .insp stills are
// JPEG files.
const std::set<std::string>& RawFrameExtensions() {
  static const std::set<std::string> extensions = {".jpg",
                                                   ".jpeg",
                                                   ".png",
                                                   ".tif",
                                                   ".tiff",
                                                   ".bmp",
                                                   ".pgm",
                                                   ".ppm",
                                                   ".pnm",
                                                   ".webp",
                                                   ".insp"};
  return extensions;
}

std::string LowerCaseExtension(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(
      extension.begin(), extension.end(), extension.begin(), [](char c) {
        return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      });
  return extension;
}

// The extension that tells OpenCV's encoder the format of a lens image
// written under the name of its raw frame (the input's format).
std::string EncoderExtension(const fs::path& name) {
  const std::string extension = LowerCaseExtension(name);
  return extension == ".insp" ? ".jpg" : extension;
}

std::vector<std::string> SplitText(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::stringstream stream(text);
  std::string part;
  while (std::getline(stream, part, separator)) {
    parts.push_back(part);
  }
  if (!text.empty() && text.back() == separator) {
    parts.push_back("");
  }
  return parts;
}

std::string Trim(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) {
    return "";
  }
  return text.substr(begin, text.find_last_not_of(" \t\r\n") - begin + 1);
}

// Lens names become folder names and JSON strings: letters, digits, '_',
// '-' and '.' only, not "." or "..", two different ones.
std::array<std::string, 2> ParseLensNames(const std::string& text) {
  const std::vector<std::string> names = SplitText(text, ',');
  if (names.size() != 2 || names[0] == names[1]) {
    throw std::invalid_argument(
        "--lens_names: expected two different names "
        "\"a,b\", got \"" +
        text + "\"");
  }
  for (const std::string& name : names) {
    const bool allowed = std::all_of(name.begin(), name.end(), [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) || c == '_' ||
             c == '-' || c == '.';
    });
    if (name.empty() || !allowed || name == "." || name == "..") {
      throw std::invalid_argument(
          "--lens_names: \"" + name +
          "\" is not a folder name of letters, digits, '_', '-', '.'");
    }
  }
  return {names[0], names[1]};
}

// The camera for rig_config.json: a model COLMAP knows and parameters it
// accepts for it, written back as given (shortest round-trip text).
std::string CameraJson(const std::string& model,
                       const std::string& params_text) {
  if (model.empty() && params_text.empty()) {
    return "";
  }
  if (model.empty() || params_text.empty()) {
    throw std::invalid_argument(
        "--camera_model and --camera_params go together (rig_configurator "
        "takes a camera only with both)");
  }
  if (!ExistsCameraModelWithName(model)) {
    throw std::invalid_argument("--camera_model: no camera model \"" + model +
                                "\"");
  }
  std::vector<double> params;
  for (const std::string& value_text : SplitText(params_text, ',')) {
    const std::string trimmed = Trim(value_text);
    char* end = nullptr;
    const double value = std::strtod(trimmed.c_str(), &end);
    if (trimmed.empty() || *end != '\0' || !std::isfinite(value)) {
      throw std::invalid_argument("--camera_params: \"" + value_text +
                                  "\" is not a number");
    }
    params.push_back(value);
  }
  const CameraModelId model_id = CameraModelNameToId(model);
  if (!CameraModelVerifyParams(model_id, params)) {
    throw std::invalid_argument(
        "--camera_params: " + std::to_string(params.size()) + " values, but " +
        model + " takes " + std::to_string(CameraModelNumParams(model_id)) +
        " (" + CameraModelParamsInfo(model_id) + ")");
  }
  std::string json = ",\n        \"camera_model_name\": \"" + model +
                     "\",\n        \"camera_params\": [";
  for (size_t i = 0; i < params.size(); ++i) {
    json += (i > 0 ? ", " : "") + ShortestDoubleText(params[i]);
  }
  return json + "]";
}

// rig_config.json for `colmap rig_configurator`: one rig, lens0 the
// reference sensor, lens1 back to back with it (cam_from_rig a rotation of
// 180 degrees about y; quaternion w, x, y, z), the same centre.
std::string RigConfigJson(const std::array<std::string, 2>& lens_names,
                          const std::string& camera_json) {
  return "[\n"
         "  {\n"
         "    \"cameras\": [\n"
         "      {\n"
         "        \"image_prefix\": \"" +
         lens_names[0] +
         "/\",\n"
         "        \"ref_sensor\": true" +
         camera_json +
         "\n"
         "      },\n"
         "      {\n"
         "        \"image_prefix\": \"" +
         lens_names[1] +
         "/\",\n"
         "        \"cam_from_rig_rotation\": [0, 0, 1, 0],\n"
         "        \"cam_from_rig_translation\": [0, 0, 0]" +
         camera_json +
         "\n"
         "      }\n"
         "    ]\n"
         "  }\n"
         "]\n";
}

// Whether PATH is FOLDER or below it (both made absolute and normal).
bool IsWithin(const fs::path& path, const fs::path& folder) {
  const fs::path relative = fs::weakly_canonical(path).lexically_relative(
      fs::weakly_canonical(folder));
  return !relative.empty() && *relative.begin() != "..";
}

// Names (relative to --input_path, '/'-separated, sorted) of the raw
// frames: those of --image_list_path, or every file below --input_path
// with a RawFrameExtensions() extension (not below --output_path).
std::vector<std::string> ListRawFrames(
    const DualFisheyeSplitterOptions& options) {
  std::vector<std::string> names;
  if (!options.image_list_path.empty()) {
    std::ifstream list(options.image_list_path);
    if (!list) {
      throw std::invalid_argument("--image_list_path: cannot read " +
                                  options.image_list_path.string());
    }
    std::set<std::string> seen;
    std::string line;
    while (std::getline(list, line)) {
      const std::string name = Trim(line);
      if (name.empty()) {
        continue;
      }
      const fs::path relative = fs::path(name).lexically_normal();
      const bool escapes =
          relative.is_absolute() || relative.empty() ||
          std::any_of(relative.begin(), relative.end(), [](const fs::path& p) {
            return p == "..";
          });
      if (escapes) {
        throw std::invalid_argument(
            "--image_list_path " + options.image_list_path.string() + ": \"" +
            name + "\" is not a path inside --input_path");
      }
      if (!fs::is_regular_file(options.input_path / relative)) {
        throw std::invalid_argument(
            "--image_list_path " + options.image_list_path.string() + ": " +
            name + ": no such file in " + options.input_path.string());
      }
      if (!seen.insert(relative.generic_string()).second) {
        throw std::invalid_argument("--image_list_path " +
                                    options.image_list_path.string() + ": " +
                                    name + " is listed twice");
      }
      names.push_back(relative.generic_string());
    }
  } else {
    for (const fs::directory_entry& entry :
         fs::recursive_directory_iterator(options.input_path)) {
      if (!entry.is_regular_file() ||
          RawFrameExtensions().count(LowerCaseExtension(entry.path())) == 0 ||
          IsWithin(entry.path(), options.output_path)) {
        continue;
      }
      names.push_back(
          entry.path().lexically_relative(options.input_path).generic_string());
    }
  }
  if (names.empty()) {
    std::string extensions;
    for (const std::string& extension : RawFrameExtensions()) {
      extensions += (extensions.empty() ? "" : " ") + extension;
    }
    throw std::invalid_argument(
        "no raw frames in " +
        (options.image_list_path.empty()
             ? options.input_path.string() + " (looked for " + extensions + ")"
             : options.image_list_path.string()));
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The raw frame NAME, decoded as stored (bit depth, channels, no EXIF
// rotation); throws naming the file when it cannot be.
cv::Mat ReadRawFrame(const fs::path& input_path, const std::string& name) {
  const fs::path path = input_path / name;
  cv::Mat raw;
  try {
    raw = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& error) {
    throw std::runtime_error(name + ": cannot read the image " + path.string() +
                             ": " + error.what());
  }
  if (raw.empty()) {
    throw std::runtime_error(name + ": cannot read the image " + path.string() +
                             " (not an image, or truncated?)");
  }
  return raw;
}

// Throws all of ERRORS (one a line, the first 20) after HEADLINE, if any.
void ThrowIfAny(const std::string& headline,
                const std::vector<std::string>& errors) {
  if (errors.empty()) {
    return;
  }
  std::string message =
      headline + " (" + std::to_string(errors.size()) + "); nothing written:";
  constexpr size_t kMaxShown = 20;
  for (size_t i = 0; i < errors.size() && i < kMaxShown; ++i) {
    message += "\n  " + errors[i];
  }
  if (errors.size() > kMaxShown) {
    message +=
        "\n  ... and " + std::to_string(errors.size() - kMaxShown) + " more";
  }
  throw std::invalid_argument(message);
}

// Files written under temporary names beside their final ones, renamed when
// all are written; anything left half-done (files, folders this made) is
// removed when it is destroyed before Commit().
class StagedOutput {
 public:
  ~StagedOutput() {
    if (committed_) {
      return;
    }
    std::error_code ignored;
    for (const auto& [temporary, final_path] : files_) {
      fs::remove(temporary, ignored);
    }
    for (const fs::path& path : renamed_) {
      fs::remove(path, ignored);
    }
    for (auto folder = created_folders_.rbegin();
         folder != created_folders_.rend();
         ++folder) {
      fs::remove(*folder, ignored);  // only if empty
    }
  }

  void Write(const fs::path& path, const std::string& bytes) {
    CreateFolders(path.parent_path());
    const fs::path temporary =
        path.string() + ".tmp-" + std::to_string(::getpid());
    files_.emplace_back(temporary, path);
    std::ofstream file(temporary, std::ios::binary);
    file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    file.close();
    if (!file) {
      throw std::runtime_error("cannot write " + temporary.string() +
                               " (disk full? no permission?)");
    }
  }

  void Commit() {
    for (const auto& [temporary, final_path] : files_) {
      std::error_code error;
      fs::rename(temporary, final_path, error);
      if (error) {
        throw std::runtime_error("cannot rename " + temporary.string() +
                                 " to " + final_path.string() + ": " +
                                 error.message());
      }
      renamed_.push_back(final_path);
    }
    committed_ = true;
  }

 private:
  void CreateFolders(const fs::path& folder) {
    if (folder.empty() || fs::is_directory(folder)) {
      return;
    }
    CreateFolders(folder.parent_path());
    std::error_code error;
    fs::create_directory(folder, error);
    if (error) {
      throw std::runtime_error("cannot create the folder " + folder.string() +
                               ": " + error.message());
    }
    created_folders_.push_back(folder);
  }

  std::vector<std::pair<fs::path, fs::path>> files_;  // temporary, final
  std::vector<fs::path> renamed_;
  std::vector<fs::path> created_folders_;
  bool committed_ = false;
};

std::string EncodeImage(const cv::Mat& image,
                        const std::string& extension,
                        const std::vector<int>& params,
                        const std::string& what) {
  std::vector<uchar> bytes;
  bool encoded = false;
  try {
    encoded = cv::imencode(extension, image, bytes, params);
  } catch (const cv::Exception& error) {
    throw std::runtime_error("cannot encode " + what + ": " + error.what());
  }
  if (!encoded) {
    throw std::runtime_error("cannot encode " + what + " as " + extension);
  }
  return std::string(bytes.begin(), bytes.end());
}

// Throws naming the output files that exist already (none may be
// overwritten) and the raw frames whose format OpenCV cannot write.
void CheckOutputsAreNew(const std::vector<std::string>& names,
                        const std::array<std::string, 2>& lens_names,
                        const fs::path& out) {
  std::vector<std::string> unwritable;
  std::vector<std::string> existing;
  for (const fs::path& path : {out / "rig_config.json", out / "circles.txt"}) {
    if (fs::exists(path)) {
      existing.push_back(path.string());
    }
  }
  for (const std::string& name : names) {
    if (!cv::haveImageWriter("x" + EncoderExtension(name))) {
      unwritable.push_back(name + ": OpenCV cannot write its format (" +
                           LowerCaseExtension(name) + ")");
    }
    for (const std::string& lens : lens_names) {
      for (const fs::path& path : {out / "images" / lens / name,
                                   out / "masks" / lens / (name + ".png")}) {
        if (fs::exists(path)) {
          existing.push_back(path.string());
        }
      }
    }
  }
  ThrowIfAny("raw frames in formats OpenCV cannot write", unwritable);
  ThrowIfAny(
      "refusing to overwrite existing output files (choose another "
      "--output_path or remove them)",
      existing);
}

// Throws naming the lens when a circle does not fit its lens image.
void CheckCircles(const std::array<ImageCircle, 2>& circles,
                  const cv::Size& raw_size,
                  const std::array<std::string, 2>& lens_names,
                  const std::string& origin) {
  for (int lens = 0; lens < 2; ++lens) {
    const std::string error =
        ImageCircleError(circles[lens], LensImageSize(raw_size));
    if (!error.empty()) {
      throw std::invalid_argument(lens_names[lens] + " (" + origin +
                                  "): " + error);
    }
  }
}

// What the first pass over the raw frames found.
struct RawFrameScan {
  cv::Size raw_size;
  // Without given circles: the circles detected in each lens, and the first
  // failure to detect one (frame name, why).
  std::array<std::vector<ImageCircle>, 2> detected;
  std::array<std::pair<std::string, std::string>, 2> first_failure;
};

// Pass 1: every frame readable, of dual-fisheye layout and of one size;
// with GIVEN_CIRCLES they are checked against the first frame's size and
// every frame is checked against them (DualFisheyeFrameError), else the
// image circles of every frame are detected. Throws naming every bad frame.
RawFrameScan ScanRawFrames(
    const DualFisheyeSplitterOptions& options,
    const std::vector<std::string>& names,
    const std::array<std::string, 2>& lens_names,
    const std::optional<std::array<ImageCircle, 2>>& given_circles) {
  RawFrameScan scan;
  std::vector<std::string> errors;
  std::string first_name;
  for (const std::string& name : names) {
    cv::Mat raw;
    try {
      raw = ReadRawFrame(options.input_path, name);
    } catch (const std::exception& error) {
      errors.push_back(error.what());
      continue;
    }
    const std::string layout_error = DualFisheyeLayoutError(raw);
    if (!layout_error.empty()) {
      errors.push_back(name + ": " + layout_error);
      continue;
    }
    if (first_name.empty()) {
      first_name = name;
      scan.raw_size = raw.size();
      if (given_circles) {
        CheckCircles(*given_circles, raw.size(), lens_names, "--circles");
      }
    } else if (raw.size() != scan.raw_size) {
      errors.push_back(name + ": " + std::to_string(raw.cols) + "x" +
                       std::to_string(raw.rows) + ", but " + first_name +
                       " is " + std::to_string(scan.raw_size.width) + "x" +
                       std::to_string(scan.raw_size.height) +
                       " (all frames must come from one camera)");
      continue;
    }
    if (given_circles) {
      const std::string error =
          DualFisheyeFrameError(raw, *given_circles, options.black_level);
      if (!error.empty()) {
        errors.push_back(name + ": " + error);
      }
      continue;
    }
    const cv::Size lens_size = LensImageSize(raw.size());
    for (int lens = 0; lens < 2; ++lens) {
      ImageCircle circle;
      const std::string error = DetectImageCircle(
          raw(cv::Rect(
              lens * lens_size.width, 0, lens_size.width, lens_size.height)),
          options.black_level,
          &circle);
      if (error.empty()) {
        scan.detected[lens].push_back(circle);
      } else if (scan.first_failure[lens].first.empty()) {
        scan.first_failure[lens] = {name, error};
      }
    }
  }
  ThrowIfAny("bad raw frames", errors);
  return scan;
}

// The image circle of each lens from the detections of SCAN: their median
// over the frames where one was found. Throws naming the lens when a
// circle was found in no frame or does not fit.
std::array<ImageCircle, 2> CirclesFromDetections(
    const RawFrameScan& scan,
    const DualFisheyeSplitterOptions& options,
    size_t num_frames,
    const std::array<std::string, 2>& lens_names) {
  std::array<ImageCircle, 2> circles;
  for (int lens = 0; lens < 2; ++lens) {
    if (scan.detected[lens].empty()) {
      const auto& [name, why] = scan.first_failure[lens];
      throw std::invalid_argument(
          name + ": " + lens_names[lens] + ": " + why +
          "; no image circle in " + lens_names[lens] + " of any of the " +
          std::to_string(num_frames) +
          " frames: not dual-fisheye frames (a normal photo or an "
          "equirectangular panorama?), or --black_level " +
          std::to_string(options.black_level) +
          " does not separate the image circle from its surround");
    }
    circles[lens] = ClampDetectedImageCircle(
        MedianImageCircle(scan.detected[lens]), LensImageSize(scan.raw_size));
  }
  CheckCircles(circles, scan.raw_size, lens_names, "detected");
  return circles;
}

// Pass 2 with detected circles: every frame is checked against them.
void CheckRawFrames(const DualFisheyeSplitterOptions& options,
                    const std::vector<std::string>& names,
                    const std::array<ImageCircle, 2>& circles) {
  std::vector<std::string> errors;
  for (const std::string& name : names) {
    try {
      const std::string error = DualFisheyeFrameError(
          ReadRawFrame(options.input_path, name), circles, options.black_level);
      if (!error.empty()) {
        errors.push_back(name + ": " + error);
      }
    } catch (const std::exception& error) {
      errors.push_back(error.what());
    }
  }
  ThrowIfAny("bad raw frames", errors);
}

// The last pass: every output file under a temporary name, then renamed.
void WriteOutputs(const DualFisheyeSplitterOptions& options,
                  const std::vector<std::string>& names,
                  const std::array<std::string, 2>& lens_names,
                  const std::array<ImageCircle, 2>& circles,
                  const cv::Size& raw_size,
                  const std::string& camera_json) {
  const fs::path& out = options.output_path;
  StagedOutput staged;
  std::array<std::string, 2> mask_bytes;  // the same for every frame
  for (int lens = 0; lens < 2; ++lens) {
    mask_bytes[lens] =
        EncodeImage(ImageCircleMask(LensImageSize(raw_size), circles[lens]),
                    ".png",
                    {},
                    lens_names[lens] + "'s mask");
  }
  for (const std::string& name : names) {
    const std::array<LensImage, 2> lenses =
        SplitDualFisheye(ReadRawFrame(options.input_path, name), circles);
    const std::string extension = EncoderExtension(name);
    std::vector<int> params;
    if (extension == ".jpg" || extension == ".jpeg") {
      params = {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality};
    }
    for (int lens = 0; lens < 2; ++lens) {
      staged.Write(out / "images" / lens_names[lens] / name,
                   EncodeImage(lenses[lens].image,
                               extension,
                               params,
                               lens_names[lens] + " of " + name));
      staged.Write(out / "masks" / lens_names[lens] / (name + ".png"),
                   mask_bytes[lens]);
    }
  }
  staged.Write(out / "rig_config.json", RigConfigJson(lens_names, camera_json));
  // The header of the renderer's circles.txt (synthetic/rig.h), so that
  // one reader takes both.
  std::string circles_text =
      "# SENSOR CX CY R (pixels, image corner at 0, 0)\n";
  for (int lens = 0; lens < 2; ++lens) {
    circles_text += lens_names[lens] + " " +
                    ShortestDoubleText(circles[lens].cx) + " " +
                    ShortestDoubleText(circles[lens].cy) + " " +
                    ShortestDoubleText(circles[lens].r) + "\n";
  }
  staged.Write(out / "circles.txt", circles_text);
  staged.Commit();
}

void SplitDualFisheyeFolder(const DualFisheyeSplitterOptions& options) {
  if (options.black_level < 0 || options.black_level > 254) {
    throw std::invalid_argument("--black_level " +
                                std::to_string(options.black_level) +
                                ": expected 0..254 (8-bit scale)");
  }
  if (options.jpeg_quality < 1 || options.jpeg_quality > 100) {
    throw std::invalid_argument("--jpeg_quality " +
                                std::to_string(options.jpeg_quality) +
                                ": expected 1..100");
  }
  const std::array<std::string, 2> lens_names =
      ParseLensNames(options.lens_names);
  const std::string camera_json =
      CameraJson(options.camera_model, options.camera_params);
  std::optional<std::array<ImageCircle, 2>> given_circles;
  if (!options.circles.empty()) {
    std::array<ImageCircle, 2> circles;
    const std::string error = ParseImageCircles(options.circles, &circles);
    if (!error.empty()) {
      throw std::invalid_argument("--circles: " + error);
    }
    given_circles = circles;
  }
  if (!fs::is_directory(options.input_path)) {
    throw std::invalid_argument("--input_path " + options.input_path.string() +
                                " is not a folder");
  }
  if (fs::exists(options.output_path) &&
      !fs::is_directory(options.output_path)) {
    throw std::invalid_argument("--output_path " +
                                options.output_path.string() +
                                " exists and is not a folder");
  }

  const std::vector<std::string> names = ListRawFrames(options);
  CheckOutputsAreNew(names, lens_names, options.output_path);
  const RawFrameScan scan =
      ScanRawFrames(options, names, lens_names, given_circles);
  std::array<ImageCircle, 2> circles;
  if (given_circles) {
    circles = *given_circles;
  } else {
    circles = CirclesFromDetections(scan, options, names.size(), lens_names);
    CheckRawFrames(options, names, circles);
  }
  for (int lens = 0; lens < 2; ++lens) {
    LOG(INFO) << "dual_fisheye_splitter: " << lens_names[lens]
              << ": image circle (cx, cy, r) = ("
              << ShortestDoubleText(circles[lens].cx) << ", "
              << ShortestDoubleText(circles[lens].cy) << ", "
              << ShortestDoubleText(circles[lens].r) << ") "
              << (given_circles
                      ? "given"
                      : "detected (median of " +
                            std::to_string(scan.detected[lens].size()) +
                            " of " + std::to_string(names.size()) + " frames)");
  }

  WriteOutputs(options, names, lens_names, circles, scan.raw_size, camera_json);
  const cv::Size lens_size = LensImageSize(scan.raw_size);
  LOG(INFO) << "dual_fisheye_splitter: " << names.size() << " raw frames -> "
            << 2 * names.size() << " lens images and masks (" << lens_size.width
            << "x" << lens_size.height << ") in "
            << options.output_path.string() << "/images/{" << lens_names[0]
            << "," << lens_names[1] << "}";
}

}  // namespace

int RunDualFisheyeSplitter(int argc, char** argv) {
  DualFisheyeSplitterOptions splitter_options;

  OptionManager options;
  options.AddRequiredOption("input_path", &splitter_options.input_path);
  options.AddRequiredOption("output_path", &splitter_options.output_path);
  options.AddDefaultOption("image_list_path",
                           &splitter_options.image_list_path,
                           "only these raw frames (names relative to "
                           "input_path, one a line)");
  options.AddDefaultOption(
      "lens_names", &splitter_options.lens_names, "left,right lens folders");
  options.AddDefaultOption("circles",
                           &splitter_options.circles,
                           "\"cx,cy,r;cx,cy,r\" image circles of the left "
                           "and right lens in lens image pixels; empty = "
                           "detect");
  options.AddDefaultOption("black_level",
                           &splitter_options.black_level,
                           "intensity (8-bit scale) at or below which a "
                           "pixel is black");
  options.AddDefaultOption("camera_model",
                           &splitter_options.camera_model,
                           "camera of both lenses in rig_config.json");
  options.AddDefaultOption("camera_params",
                           &splitter_options.camera_params,
                           "its parameters, comma-separated");
  options.AddDefaultOption("jpeg_quality", &splitter_options.jpeg_quality);
  if (!options.Parse(argc, argv)) {
    return EXIT_FAILURE;
  }

  try {
    SplitDualFisheyeFolder(splitter_options);
  } catch (const std::exception& error) {
    LOG(ERROR) << "dual_fisheye_splitter: " << error.what();
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace colmap
