#include "colmap_ext/controllers/dual_fisheye_splitting.h"

#include "calibration/camera_presets.h"
#include "colmap/sensor/models.h"
#include "colmap/util/logging.h"
#include "colmap_ext/controllers/image_errors.h"
#include "colmap_ext/image/dual_fisheye_split.h"
#include "colmap_ext/image/flat_field.h"
#include "colmap_ext/scene/camera_params_error.h"
#include "colmap_ext/util/file_output.h"
#include "synthetic/file_formats.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <unistd.h>

namespace colmap {
namespace {

namespace fs = std::filesystem;

using sphera::EncoderExtension;
using sphera::ImageFileExtensions;
using sphera::IsImageFileName;
using sphera::LowerCaseExtension;

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

// The numbers of --camera_params.
std::vector<double> CameraParamsValues(const std::string& params_text) {
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
  return params;
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
  const std::vector<double> params = CameraParamsValues(params_text);
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

// The files of one frame: a side-by-side raw frame, or one file per lens
// (either may be missing in an incomplete frame).
struct FrameFiles {
  std::string name;  // relative, '/'-separated: the output files' name
  fs::path raw;
  std::array<std::optional<fs::path>, 2> lens_files;

  bool SideBySide() const { return !raw.empty(); }
  bool Complete() const {
    return SideBySide() || (lens_files[0] && lens_files[1]);
  }
};

// Names (relative to FOLDER, '/'-separated, sorted) of the image files
// below FOLDER (ImageFileExtensions(); none below EXCLUDED).
std::vector<std::string> ListImageFiles(const fs::path& folder,
                                        const fs::path& excluded) {
  std::vector<std::string> names;
  for (const fs::directory_entry& entry :
       fs::recursive_directory_iterator(folder)) {
    if (!entry.is_regular_file() ||
        !IsImageFileName(entry.path().string()) ||
        IsWithin(entry.path(), excluded)) {
      continue;
    }
    names.push_back(entry.path().lexically_relative(folder).generic_string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The names of --image_list_path (checked: inside input_path, existing,
// each once).
std::vector<std::string> ReadImageList(const fs::path& list_path,
                                       const fs::path& input_path) {
  std::ifstream list(list_path);
  if (!list) {
    throw std::invalid_argument("--image_list_path: cannot read " +
                                list_path.string());
  }
  std::vector<std::string> names;
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
    const std::string where = "--image_list_path " + list_path.string() + ": ";
    if (escapes) {
      throw std::invalid_argument(where + "\"" + name +
                                  "\" is not a path inside --input_path");
    }
    if (!fs::is_regular_file(input_path / relative)) {
      throw std::invalid_argument(where + name + ": no such file in " +
                                  input_path.string());
    }
    if (!seen.insert(relative.generic_string()).second) {
      throw std::invalid_argument(where + name + " is listed twice");
    }
    names.push_back(relative.generic_string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The lens tag of two folders' file names: at POSITION, FRONT in the front
// lens's names where BACK is in the back lens's (both empty: the same
// names).
struct LensTag {
  size_t position = 0;
  std::string front;
  std::string back;
};

// The tag that most pairs of a front and a back name differ by, among pairs
// near each other in sorted order (a missing file shifts the order by one)
// that differ in one place by at most kMaxTagLength characters.
LensTag FindLensTag(const std::vector<std::string>& fronts,
                    const std::vector<std::string>& backs) {
  constexpr size_t kMaxTagLength = 8;
  constexpr int kNeighbours = 8;
  std::map<std::tuple<size_t, std::string, std::string>, int> votes;
  for (int i = 0; i < static_cast<int>(fronts.size()); ++i) {
    const int j_end = std::min(static_cast<int>(backs.size()), i + kNeighbours);
    for (int j = std::max(0, i - kNeighbours); j < j_end; ++j) {
      const std::string& front = fronts[i];
      const std::string& back = backs[j];
      if (front == back) {
        ++votes[{0, "", ""}];
        continue;
      }
      const size_t shorter = std::min(front.size(), back.size());
      size_t prefix = 0;
      while (prefix < shorter && front[prefix] == back[prefix]) {
        ++prefix;
      }
      size_t suffix = 0;
      while (suffix < shorter - prefix && front[front.size() - 1 - suffix] ==
                                              back[back.size() - 1 - suffix]) {
        ++suffix;
      }
      const std::string front_tag =
          front.substr(prefix, front.size() - prefix - suffix);
      const std::string back_tag =
          back.substr(prefix, back.size() - prefix - suffix);
      if (front_tag.size() <= kMaxTagLength &&
          back_tag.size() <= kMaxTagLength &&
          front_tag.find('/') == std::string::npos &&
          back_tag.find('/') == std::string::npos) {
        ++votes[{prefix, front_tag, back_tag}];
      }
    }
  }
  LensTag tag;
  int most = 0;
  for (const auto& [key, count] : votes) {
    if (count > most) {
      most = count;
      tag = {std::get<0>(key), std::get<1>(key), std::get<2>(key)};
    }
  }
  return tag;
}

// NAME without TAG at POSITION, or nothing when it has no TAG there.
std::optional<std::string> RemoveTag(const std::string& name,
                                     size_t position,
                                     const std::string& tag) {
  if (name.compare(position, tag.size(), tag) != 0 ||
      position + tag.size() > name.size()) {
    return std::nullopt;
  }
  return name.substr(0, position) + name.substr(position + tag.size());
}

// Adds lens LENS's file PATH to the frame NAME of FRAMES; a second file of
// the same lens for one frame is an error.
void AddLensFile(const std::string& name,
                 int lens,
                 const fs::path& path,
                 std::map<std::string, FrameFiles>* frames,
                 std::vector<std::string>* errors) {
  FrameFiles& frame = (*frames)[name];
  frame.name = name;
  if (frame.lens_files[lens]) {
    errors->push_back(
        "frame " + name + ": two files of lens " + std::to_string(lens) + ", " +
        frame.lens_files[lens]->string() + " and " + path.string());
    return;
  }
  frame.lens_files[lens] = path;
}

std::vector<FrameFiles> FramesOfTwoFolders(
    const DualFisheyeSplittingOptions& options) {
  const std::vector<std::string> fronts =
      ListImageFiles(options.front_path, options.output_path);
  const std::vector<std::string> backs =
      ListImageFiles(options.back_path, options.output_path);
  const LensTag tag = FindLensTag(fronts, backs);
  if (!tag.front.empty() || !tag.back.empty()) {
    LOG(INFO) << "dual_fisheye_splitter: the lens tag of the file names: \""
              << tag.front << "\" (front) and \"" << tag.back << "\" (back)";
  }
  std::map<std::string, FrameFiles> frames;
  std::vector<std::string> errors;
  const std::array<const std::vector<std::string>*, 2> names = {&fronts,
                                                                &backs};
  const std::array<const fs::path*, 2> folders = {&options.front_path,
                                                  &options.back_path};
  for (int lens = 0; lens < 2; ++lens) {
    const std::string& lens_tag = lens == 0 ? tag.front : tag.back;
    for (const std::string& name : *names[lens]) {
      // A name without the tag is a frame of its own (and one lens).
      const std::string frame_name =
          RemoveTag(name, tag.position, lens_tag).value_or(name);
      AddLensFile(frame_name, lens, *folders[lens] / name, &frames, &errors);
    }
  }
  ThrowIfAny("files of one lens that fall on one frame", errors);
  std::vector<FrameFiles> list;
  for (auto& [name, frame] : frames) {
    list.push_back(std::move(frame));
  }
  return list;
}

std::vector<FrameFiles> FramesOfSuffixes(
    const DualFisheyeSplittingOptions& options,
    const std::vector<std::string>& names) {
  const std::vector<std::string> suffixes =
      SplitText(options.lens_suffixes, ',');
  std::map<std::string, FrameFiles> frames;
  std::vector<std::string> errors;
  for (const std::string& name : names) {
    const fs::path path(name);
    const std::string stem = path.stem().string();
    int lens = -1;
    for (int l = 0; l < 2; ++l) {
      if (stem.size() > suffixes[l].size() &&
          stem.compare(stem.size() - suffixes[l].size(),
                       suffixes[l].size(),
                       suffixes[l]) == 0 &&
          (lens < 0 || suffixes[l].size() > suffixes[lens].size())) {
        lens = l;
      }
    }
    if (lens < 0) {
      errors.push_back(name + ": its name ends in neither \"" + suffixes[0] +
                       "\" nor \"" + suffixes[1] + "\" (--lens_suffixes)");
      continue;
    }
    const std::string frame_name =
        (path.parent_path() /
         (stem.substr(0, stem.size() - suffixes[lens].size()) +
          path.extension().string()))
            .generic_string();
    AddLensFile(frame_name, lens, options.input_path / name, &frames, &errors);
  }
  ThrowIfAny("files that are no lens's", errors);
  std::vector<FrameFiles> list;
  for (auto& [name, frame] : frames) {
    list.push_back(std::move(frame));
  }
  return list;
}

// The frames OPTIONS name, sorted by name; incomplete ones are errors
// unless allowed (then each is named in a warning).
std::vector<FrameFiles> ListFrames(const DualFisheyeSplittingOptions& options) {
  std::vector<FrameFiles> frames;
  if (!options.front_path.empty()) {
    frames = FramesOfTwoFolders(options);
  } else {
    const std::vector<std::string> names =
        options.image_list_path.empty()
            ? ListImageFiles(options.input_path, options.output_path)
            : ReadImageList(options.image_list_path, options.input_path);
    if (!options.lens_suffixes.empty()) {
      frames = FramesOfSuffixes(options, names);
    } else {
      for (const std::string& name : names) {
        frames.push_back({name, options.input_path / name, {}});
      }
    }
  }
  if (frames.empty()) {
    std::string extensions;
    for (const std::string& extension : ImageFileExtensions()) {
      extensions += (extensions.empty() ? "" : " ") + extension;
    }
    const std::string where =
        !options.front_path.empty()
            ? options.front_path.string() + " and " + options.back_path.string()
        : options.image_list_path.empty() ? options.input_path.string()
                                          : options.image_list_path.string();
    throw std::invalid_argument("no raw frames in " + where + " (looked for " +
                                extensions + ")");
  }
  std::vector<std::string> incomplete;
  for (const FrameFiles& frame : frames) {
    if (frame.Complete()) {
      continue;
    }
    const int present = frame.lens_files[0] ? 0 : 1;
    incomplete.push_back(
        "frame " + frame.name + ": " + frame.lens_files[present]->string() +
        ", but no file of " +
        (present == 0 ? "the back lens (lens 1)" : "the front lens (lens 0)"));
  }
  if (!options.allow_incomplete_frames) {
    ThrowIfAny(
        "frames with a lens file missing (--allow_incomplete_frames 1 writes "
        "their one lens)",
        incomplete);
  }
  for (const std::string& message : incomplete) {
    LOG(WARNING) << "dual_fisheye_splitter: " << message;
  }
  return frames;
}

// PATH decoded as stored (bit depth, channels, no EXIF rotation); throws
// naming the file when it cannot be. A JPEG or PNG cut short or overwritten,
// which OpenCV decodes with gray where its data is missing, is refused
// (ImageFileError, as feature extraction does).
cv::Mat ReadImage(const fs::path& path) {
  if (const std::string error = ImageFileError(path); !error.empty()) {
    throw std::runtime_error("cannot read the image " + path.string() + ": " +
                             error);
  }
  cv::Mat image;
  try {
    image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& error) {
    throw std::runtime_error("cannot read the image " + path.string() + ": " +
                             error.what());
  }
  if (image.empty()) {
    throw std::runtime_error("cannot read the image " + path.string() +
                             " (not an image, or truncated?)");
  }
  return image;
}

// The lens images of FRAME (empty for a missing lens file); throws naming
// the frame when a file cannot be read or is no lens image.
std::array<cv::Mat, 2> ReadLensImages(const FrameFiles& frame) {
  try {
    if (frame.SideBySide()) {
      const cv::Mat raw = ReadImage(frame.raw);
      if (const std::string error = DualFisheyeLayoutError(raw);
          !error.empty()) {
        throw std::invalid_argument(error);
      }
      return LensImagesOfRawFrame(raw);
    }
    std::array<cv::Mat, 2> lenses;
    for (int lens = 0; lens < 2; ++lens) {
      if (frame.lens_files[lens]) {
        lenses[lens] = ReadImage(*frame.lens_files[lens]);
        if (const std::string error = LensImageError(lenses[lens]);
            !error.empty()) {
          throw std::invalid_argument(frame.lens_files[lens]->string() + ": " +
                                      error);
        }
      }
    }
    return lenses;
  } catch (const std::exception& error) {
    throw std::invalid_argument(frame.name + ": " + error.what());
  }
}

// Why the lens images of FRAME are not a dual-fisheye frame with CIRCLES
// (of an incomplete frame, its one lens), or "".
std::string FrameError(const std::array<cv::Mat, 2>& lenses,
                       const std::array<ImageCircle, 2>& circles,
                       int black_level) {
  if (!lenses[0].empty() && !lenses[1].empty()) {
    return DualFisheyeFrameError(lenses, circles, black_level);
  }
  const int lens = lenses[0].empty() ? 1 : 0;
  const std::string error =
      LensImageCircleError(lenses[lens], circles[lens], black_level);
  return error.empty() ? "" : "lens " + std::to_string(lens) + ": " + error;
}

std::string SizeText(const cv::Size& size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

// Throws naming the output files that exist already (none may be
// overwritten) and the frames whose format OpenCV cannot write.
void CheckOutputsAreNew(const std::vector<FrameFiles>& frames,
                        const std::array<std::string, 2>& lens_names,
                        const fs::path& out) {
  std::vector<std::string> unwritable;
  std::vector<std::string> existing;
  for (const fs::path& path : {out / "rig_config.json", out / "circles.txt"}) {
    if (fs::exists(path)) {
      existing.push_back(path.string());
    }
  }
  for (const FrameFiles& frame : frames) {
    if (!cv::haveImageWriter("x" + EncoderExtension(frame.name))) {
      unwritable.push_back(frame.name + ": OpenCV cannot write its format (" +
                           LowerCaseExtension(frame.name) + ")");
    }
    for (const std::string& lens : lens_names) {
      for (const fs::path& path :
           {out / "images" / lens / frame.name,
            out / "masks" / lens / (frame.name + ".png")}) {
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

// What the first pass over the frames found.
struct FrameScan {
  cv::Size lens_size;
  // Without given circles: the circles detected in each lens, and the first
  // failure to detect one (frame name, why).
  std::array<std::vector<ImageCircle>, 2> detected;
  std::array<std::pair<std::string, std::string>, 2> first_failure;
};

// Pass 1: every frame readable, of one lens image size; with GIVEN_CIRCLES
// they are checked against the first frame's size and every frame against
// them, else the image circles of every frame are detected. Throws naming
// every bad frame.
FrameScan ScanFrames(
    const std::vector<FrameFiles>& frames,
    const std::array<std::string, 2>& lens_names,
    const std::optional<std::array<ImageCircle, 2>>& given_circles,
    int black_level) {
  FrameScan scan;
  std::vector<std::string> errors;
  std::string first_name;
  for (const FrameFiles& frame : frames) {
    std::array<cv::Mat, 2> lenses;
    try {
      lenses = ReadLensImages(frame);
    } catch (const std::exception& error) {
      errors.push_back(error.what());
      continue;
    }
    const cv::Size size = (lenses[0].empty() ? lenses[1] : lenses[0]).size();
    if (first_name.empty()) {
      first_name = frame.name;
      scan.lens_size = size;
      if (given_circles) {
        for (int lens = 0; lens < 2; ++lens) {
          if (const std::string error =
                  ImageCircleError((*given_circles)[lens], size);
              !error.empty()) {
            throw std::invalid_argument(lens_names[lens] +
                                        " (--circles): " + error);
          }
        }
      }
    }
    if (frame.SideBySide() && size != scan.lens_size) {
      const cv::Size raw_size(2 * size.width, size.height);
      errors.push_back(
          frame.name + ": " + SizeText(raw_size) + ", but " + first_name +
          " is " + SizeText({2 * scan.lens_size.width, scan.lens_size.height}) +
          " (all frames must come from one camera)");
      continue;
    }
    bool size_error = false;
    for (int lens = 0; lens < 2; ++lens) {
      if (!lenses[lens].empty() && lenses[lens].size() != scan.lens_size) {
        errors.push_back(frame.name + ": " + lens_names[lens] + " is " +
                         SizeText(lenses[lens].size()) + ", but " + first_name +
                         "'s lens images are " + SizeText(scan.lens_size) +
                         " (all frames must come from one camera)");
        size_error = true;
        break;
      }
    }
    if (size_error) {
      continue;
    }
    if (given_circles) {
      if (const std::string error =
              FrameError(lenses, *given_circles, black_level);
          !error.empty()) {
        errors.push_back(frame.name + ": " + error);
      }
      continue;
    }
    for (int lens = 0; lens < 2; ++lens) {
      if (lenses[lens].empty()) {
        continue;
      }
      ImageCircle circle;
      const std::string error =
          DetectImageCircle(lenses[lens], black_level, &circle);
      if (error.empty()) {
        scan.detected[lens].push_back(circle);
      } else if (scan.first_failure[lens].first.empty()) {
        scan.first_failure[lens] = {frame.name, error};
      }
    }
  }
  ThrowIfAny("bad raw frames", errors);
  return scan;
}

// The image circle of each lens from the detections of SCAN: their median
// over the frames where one was found. Throws naming the lens when a
// circle was found in no frame or cannot be a lens's.
std::array<ImageCircle, 2> CirclesFromDetections(
    const FrameScan& scan,
    size_t num_frames,
    const std::array<std::string, 2>& lens_names,
    int black_level) {
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
          std::to_string(black_level) +
          " is not below the picture at the rim (or give --circles)");
    }
    circles[lens] = MedianImageCircle(scan.detected[lens]);
    if (const std::string error =
            ImageCircleError(circles[lens], scan.lens_size);
        !error.empty()) {
      throw std::invalid_argument(lens_names[lens] + " (detected): " + error);
    }
  }
  return circles;
}

// Pass 2 with detected circles: every frame is checked against them.
void CheckFrames(const std::vector<FrameFiles>& frames,
                 const std::array<ImageCircle, 2>& circles,
                 int black_level) {
  std::vector<std::string> errors;
  for (const FrameFiles& frame : frames) {
    try {
      if (const std::string error =
              FrameError(ReadLensImages(frame), circles, black_level);
          !error.empty()) {
        errors.push_back(frame.name + ": " + error);
      }
    } catch (const std::exception& error) {
      errors.push_back(error.what());
    }
  }
  ThrowIfAny("bad raw frames", errors);
}

// The header of the renderer's circles.txt (synthetic/rig.h), so that one
// reader takes both.
std::string CirclesText(const std::vector<std::string>& lens_names,
                        const std::vector<ImageCircle>& circles) {
  std::string text = "# SENSOR CX CY R (pixels, image corner at 0, 0)\n";
  for (size_t lens = 0; lens < circles.size(); ++lens) {
    text += lens_names[lens] + " " + ShortestDoubleText(circles[lens].cx) +
            " " + ShortestDoubleText(circles[lens].cy) + " " +
            ShortestDoubleText(circles[lens].r) + "\n";
  }
  return text;
}

// The fall-off ESTIMATOR fitted, logged for LENS_NAME.
RadialFalloff FitFalloff(const RadialFalloffEstimator& estimator,
                         const std::string& lens_name) {
  std::string why;
  const RadialFalloff falloff = estimator.Fit(3, 0.03, &why);
  if (falloff.IsIdentity()) {
    LOG(INFO) << "dual_fisheye_splitter: " << lens_name
              << ": no light fall-off divided out (" << why << ")";
  } else {
    LOG(INFO) << "dual_fisheye_splitter: " << lens_name
              << ": light fall-off from " << estimator.NumImages()
              << " images, the rim at " << std::lround(100 * falloff.Gain(1))
              << "% of the centre (1 + " << ShortestDoubleText(falloff.a)
              << " rho^2 + " << ShortestDoubleText(falloff.b)
              << " rho^4); divided out";
  }
  return falloff;
}

// Every STEP-th of COUNT images, so that at most 60 are read (evenly
// spread) to estimate a lens's fall-off.
size_t FalloffSampleStep(size_t count) {
  return std::max<size_t>(1, (count + 59) / 60);
}

// Each lens's light fall-off from at most 60 of the frames (evenly spread),
// logged per lens.
std::array<RadialFalloff, 2> EstimateFalloffs(
    const std::vector<FrameFiles>& frames,
    const std::array<std::string, 2>& lens_names,
    const std::array<ImageCircle, 2>& circles,
    int black_level) {
  std::array<RadialFalloffEstimator, 2> estimators = {
      RadialFalloffEstimator(circles[0], black_level),
      RadialFalloffEstimator(circles[1], black_level)};
  const size_t step = FalloffSampleStep(frames.size());
  for (size_t i = 0; i < frames.size(); i += step) {
    const std::array<cv::Mat, 2> lenses = ReadLensImages(frames[i]);
    for (int lens = 0; lens < 2; ++lens) {
      if (!lenses[lens].empty()) estimators[lens].Add(lenses[lens]);
    }
  }
  return {FitFalloff(estimators[0], lens_names[0]),
          FitFalloff(estimators[1], lens_names[1])};
}

// The last pass: every output file under a temporary name, then renamed.
void WriteOutputs(const DualFisheyeSplittingOptions& options,
                  const std::vector<FrameFiles>& frames,
                  const std::array<std::string, 2>& lens_names,
                  const std::array<ImageCircle, 2>& circles,
                  const std::array<RadialFalloff, 2>& falloffs,
                  const cv::Size& lens_size,
                  const std::string& rig_config) {
  const fs::path& out = options.output_path;
  StagedOutput staged;
  std::array<std::string, 2> mask_bytes;  // the same for every frame
  for (int lens = 0; lens < 2; ++lens) {
    mask_bytes[lens] = EncodeImage(ImageCircleMask(lens_size, circles[lens]),
                                   ".png",
                                   {},
                                   lens_names[lens] + "'s mask");
  }
  for (const FrameFiles& frame : frames) {
    const std::array<cv::Mat, 2> lenses = ReadLensImages(frame);
    const std::string extension = EncoderExtension(frame.name);
    const std::vector<int> params =
        sphera::ImageWriteParams(extension, options.jpeg_quality);
    for (int lens = 0; lens < 2; ++lens) {
      if (lenses[lens].empty()) {
        continue;
      }
      LensImage cut = CutImageCircle(lenses[lens], circles[lens]);
      DivideByFalloff(circles[lens], falloffs[lens], &cut.image);
      staged.Write(out / "images" / lens_names[lens] / frame.name,
                   EncodeImage(cut.image,
                               extension,
                               params,
                               lens_names[lens] + " of " + frame.name));
      staged.Write(out / "masks" / lens_names[lens] / (frame.name + ".png"),
                   mask_bytes[lens]);
    }
  }
  staged.Write(out / "rig_config.json", rig_config);
  staged.Write(out / "circles.txt",
               CirclesText({lens_names[0], lens_names[1]},
                           {circles[0], circles[1]}));
  staged.Commit();
}

// The preset's image circles for the frames' lens images (of the first
// readable frame; ScanFrames refuses frames of another size), and its
// resolution; nothing when no frame can be read (ScanFrames names them);
// throws naming the frame when the preset knows no such size.
std::optional<std::pair<std::array<ImageCircle, 2>, sphera::PresetResolution>>
PresetCircles(const sphera::CameraPreset& preset,
              const std::vector<FrameFiles>& frames) {
  for (const FrameFiles& frame : frames) {
    std::array<cv::Mat, 2> lenses;
    try {
      lenses = ReadLensImages(frame);
    } catch (const std::exception&) {
      continue;  // ScanFrames names it
    }
    const cv::Size size = (lenses[0].empty() ? lenses[1] : lenses[0]).size();
    // The size of the file the preset stores: both lenses side by side, or
    // one lens.
    const int lenses_per_file =
        preset.storage == sphera::LensStorage::kSideBySide ? 2 : 1;
    sphera::PresetResolution resolution;
    try {
      resolution = sphera::FindPresetResolution(
          preset, lenses_per_file * size.width, size.height);
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(frame.name + ": lens images " +
                                  SizeText(size) + ": " + error.what());
    }
    std::array<ImageCircle, 2> circles;
    for (int lens = 0; lens < 2; ++lens) {
      const sphera::PresetCircle& circle = resolution.circles.at(lens);
      circles[lens] = {circle.cx, circle.cy, circle.r};
    }
    return std::make_pair(circles, resolution);
  }
  return std::nullopt;
}

// How far the farthest of CIRCLES is from MEDIAN (centre distance plus
// radius difference, pixels).
double LargestDeviation(const std::vector<ImageCircle>& circles,
                        const ImageCircle& median) {
  double largest = 0;
  for (const ImageCircle& circle : circles) {
    largest =
        std::max(largest,
                 std::hypot(circle.cx - median.cx, circle.cy - median.cy) +
                     std::abs(circle.r - median.r));
  }
  return largest;
}

// A preset that stores one file per lens (the Vuze's NAME_1.JPG ...
// NAME_8.JPG in one folder): nothing to split. Every file is read and
// checked first (a lens suffix of the preset, a size of the preset, every
// lens of each frame unless allow_incomplete_frames, no existing output);
// then each is cut to its lens's image circle (the preset's at that size),
// with flat_field divided by its lens's fall-off, and written under its
// own name beside its mask, with the preset's rig config.
void WriteLensFiles(const DualFisheyeSplittingOptions& options,
                    const sphera::CameraPreset& preset) {
  const fs::path& out = options.output_path;
  const std::vector<std::string> names =
      options.image_list_path.empty()
          ? ListImageFiles(options.input_path, out)
          : ReadImageList(options.image_list_path, options.input_path);
  if (names.empty()) {
    throw std::invalid_argument("no lens files in " +
                                options.input_path.string());
  }
  const int num_lenses = static_cast<int>(preset.lenses.size());
  std::string suffixes;
  for (const sphera::PresetLens& lens : preset.lenses) {
    suffixes += (suffixes.empty() ? "" : ", ") + lens.file_suffix;
  }
  struct LensFile {
    std::string name;
    int lens = -1;
  };
  std::vector<LensFile> files;
  std::map<std::string, std::set<int>> frames;  // frame name -> its lenses
  std::vector<std::string> errors;
  for (const std::string& name : names) {
    LensFile file{name};
    for (int lens = 0; lens < num_lenses && file.lens < 0; ++lens) {
      const std::string& suffix = preset.lenses[lens].file_suffix;
      if (name.size() > suffix.size() &&
          name.compare(name.size() - suffix.size(), suffix.size(), suffix) ==
              0) {
        file.lens = lens;
        frames[name.substr(0, name.size() - suffix.size())].insert(lens);
      }
    }
    if (file.lens < 0) {
      errors.push_back(name + ": not a lens file of the " + preset.name +
                       " (its name ends in none of " + suffixes + ")");
    }
    files.push_back(file);
  }
  std::vector<std::string> incomplete;
  for (const auto& [frame, lenses] : frames) {
    for (int lens = 0; lens < num_lenses; ++lens) {
      if (!lenses.count(lens)) {
        incomplete.push_back("frame " + frame + ": no file " + frame +
                             preset.lenses[lens].file_suffix + " of lens " +
                             std::to_string(lens + 1));
      }
    }
  }
  if (options.allow_incomplete_frames) {
    for (const std::string& message : incomplete) {
      LOG(WARNING) << "dual_fisheye_splitter: " << message;
    }
  } else {
    errors.insert(errors.end(), incomplete.begin(), incomplete.end());
    if (!incomplete.empty()) {
      errors.push_back("(--allow_incomplete_frames 1 writes the lenses a "
                       "frame has)");
    }
  }
  // Every file readable, a lens image, of one size the preset knows.
  std::optional<cv::Size> size;
  for (const LensFile& file : files) {
    if (file.lens < 0) {
      continue;
    }
    try {
      const cv::Mat image = ReadImage(options.input_path / file.name);
      if (const std::string error = LensImageError(image); !error.empty()) {
        throw std::invalid_argument(error);
      }
      if (!size) {
        size = image.size();
      } else if (image.size() != *size) {
        throw std::invalid_argument(SizeText(image.size()) + ", not the " +
                                    SizeText(*size) + " of the first file");
      }
      if (!cv::haveImageWriter("x" + EncoderExtension(file.name))) {
        throw std::invalid_argument("OpenCV cannot write its format (" +
                                    LowerCaseExtension(file.name) + ")");
      }
    } catch (const std::exception& error) {
      errors.push_back(file.name + ": " + error.what());
    }
  }
  ThrowIfAny("files that are not usable lens files of the " + preset.name,
             errors);
  sphera::PresetResolution resolution;
  try {
    resolution =
        sphera::FindPresetResolution(preset, size->width, size->height);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(options.input_path.string() + ": lens files " +
                                SizeText(*size) + ": " + error.what());
  }
  std::vector<ImageCircle> circles;
  std::vector<std::string> lens_names;  // as circles.txt names them
  for (int lens = 0; lens < num_lenses; ++lens) {
    const sphera::PresetCircle& circle = resolution.circles.at(lens);
    circles.push_back({circle.cx, circle.cy, circle.r});
    lens_names.push_back("lens" + std::to_string(lens + 1));
  }
  std::vector<std::string> existing;
  for (const fs::path& path : {out / "rig_config.json", out / "circles.txt"}) {
    if (fs::exists(path)) {
      existing.push_back(path.string());
    }
  }
  for (const LensFile& file : files) {
    for (const fs::path& path :
         {out / "images" / file.name, out / "masks" / (file.name + ".png")}) {
      if (fs::exists(path)) {
        existing.push_back(path.string());
      }
    }
  }
  ThrowIfAny(
      "refusing to overwrite existing output files (choose another "
      "--output_path or remove them)",
      existing);

  std::vector<RadialFalloff> falloffs(num_lenses);
  if (options.flat_field) {
    for (int lens = 0; lens < num_lenses; ++lens) {
      std::vector<const LensFile*> of_lens;
      for (const LensFile& file : files) {
        if (file.lens == lens) of_lens.push_back(&file);
      }
      RadialFalloffEstimator estimator(circles[lens], options.black_level);
      const size_t step = FalloffSampleStep(of_lens.size());
      for (size_t i = 0; i < of_lens.size(); i += step) {
        estimator.Add(ReadImage(options.input_path / of_lens[i]->name));
      }
      falloffs[lens] = FitFalloff(estimator, lens_names[lens]);
    }
  }

  StagedOutput staged;
  std::vector<std::string> mask_bytes(num_lenses);
  for (int lens = 0; lens < num_lenses; ++lens) {
    mask_bytes[lens] = EncodeImage(ImageCircleMask(*size, circles[lens]),
                                   ".png", {}, lens_names[lens] + "'s mask");
  }
  for (const LensFile& file : files) {
    const std::string extension = EncoderExtension(file.name);
    LensImage cut = CutImageCircle(ReadImage(options.input_path / file.name),
                                   circles[file.lens]);
    DivideByFalloff(circles[file.lens], falloffs[file.lens], &cut.image);
    staged.Write(out / "images" / file.name,
                 EncodeImage(cut.image, extension,
                             sphera::ImageWriteParams(extension,
                                                      options.jpeg_quality),
                             file.name));
    staged.Write(out / "masks" / (file.name + ".png"), mask_bytes[file.lens]);
  }
  staged.Write(out / "rig_config.json",
               sphera::PresetRigConfigJson(preset, resolution, {},
                                           options.camera_model));
  staged.Write(out / "circles.txt", CirclesText(lens_names, circles));
  staged.Commit();
  LOG(INFO) << "dual_fisheye_splitter: " << preset.name << " "
            << resolution.name << ": " << files.size() << " lens files of "
            << frames.size() << " frames -> lens images and masks ("
            << SizeText(*size) << ") in " << out.string()
            << "/images; circles " << resolution.source;
}

}  // namespace

void DualFisheyeSplittingOptions::Check() const {
  if (black_level < 0 || black_level > 254) {
    throw std::invalid_argument("--black_level " + std::to_string(black_level) +
                                ": expected 0..254 (8-bit scale)");
  }
  if (jpeg_quality < 1 || jpeg_quality > 100) {
    throw std::invalid_argument(
        "--jpeg_quality " + std::to_string(jpeg_quality) + ": expected 1..100");
  }
  if (front_path.empty() != back_path.empty()) {
    throw std::invalid_argument(
        "--front_path and --back_path go together (one folder per lens)");
  }
  if (front_path.empty() == input_path.empty()) {
    throw std::invalid_argument(
        "give either --input_path (side-by-side frames, or with "
        "--lens_suffixes one file per lens) or --front_path and --back_path");
  }
  if (!front_path.empty() &&
      (!image_list_path.empty() || !lens_suffixes.empty())) {
    throw std::invalid_argument(
        "--image_list_path and --lens_suffixes go with --input_path, not "
        "with --front_path and --back_path");
  }
  if (!lens_suffixes.empty()) {
    const std::vector<std::string> suffixes = SplitText(lens_suffixes, ',');
    if (suffixes.size() != 2 || suffixes[0].empty() || suffixes[1].empty() ||
        suffixes[0] == suffixes[1] ||
        lens_suffixes.find('/') != std::string::npos) {
      throw std::invalid_argument(
          "--lens_suffixes: expected two different file name endings "
          "\"s0,s1\" (such as \"_0,_1\"), got \"" +
          lens_suffixes + "\"");
    }
  }
  const std::pair<const char*, const fs::path*> folders[] = {
      {"--input_path", &input_path},
      {"--front_path", &front_path},
      {"--back_path", &back_path}};
  for (const auto& [option, folder] : folders) {
    if (!folder->empty() && !fs::is_directory(*folder)) {
      throw std::invalid_argument(std::string(option) + " " + folder->string() +
                                  " is not a folder");
    }
  }
  if (fs::exists(output_path) && !fs::is_directory(output_path)) {
    throw std::invalid_argument("--output_path " + output_path.string() +
                                " exists and is not a folder");
  }
  ParseLensNames(lens_names);
  if (camera.empty()) {
    CameraJson(camera_model, camera_params);
  } else {
    const sphera::CameraPreset& preset = sphera::FindCameraPreset(camera);
    if (!circles.empty() || !camera_params.empty()) {
      throw std::invalid_argument(
          "--camera " + camera +
          " gives the circles and the lens parameters; not with --circles "
          "or --camera_params (--camera_model alone picks the lenses' "
          "starting model)");
    }
    if (const std::string error =
            sphera::PresetLensModelError(preset, camera_model);
        !error.empty()) {
      throw std::invalid_argument(error);
    }
    if (preset.storage == sphera::LensStorage::kFilePerLens) {
      if (input_path.empty() || !lens_suffixes.empty() ||
          lens_names != "lens0,lens1") {
        throw std::invalid_argument(
            "--camera " + preset.name +
            ": one file per lens in --input_path (named as the camera "
            "names them); not with --front_path, --back_path, "
            "--lens_suffixes or --lens_names");
      }
    } else if (preset.storage == sphera::LensStorage::kEquirectangular ||
               preset.lenses.size() != 2) {
      throw std::invalid_argument(
          "--camera " + preset.name + ": " + std::to_string(
              preset.lenses.size()) + " lens(es), " +
          sphera::LensStorageName(preset.storage) +
          ": nothing to split (colmap rig_preset --camera " + preset.name +
          " writes its rig config)");
    }
  }
  if (!circles.empty()) {
    std::array<ImageCircle, 2> parsed;
    if (const std::string error = ParseImageCircles(circles, &parsed);
        !error.empty()) {
      throw std::invalid_argument("--circles: " + error);
    }
    for (int lens = 0; lens < 2; ++lens) {
      if (!(parsed[lens].r > 0)) {
        throw std::invalid_argument(
            "--circles: the radius of lens " + std::to_string(lens) +
            " must be > 0, got " + ShortestDoubleText(parsed[lens].r));
      }
    }
  }
}

void SplitDualFisheyeFrames(const DualFisheyeSplittingOptions& options) {
  options.Check();
  if (!options.camera.empty()) {
    const sphera::CameraPreset& preset =
        sphera::FindCameraPreset(options.camera);
    if (preset.storage == sphera::LensStorage::kFilePerLens) {
      WriteLensFiles(options, preset);
      return;
    }
  }
  const std::array<std::string, 2> lens_names =
      ParseLensNames(options.lens_names);
  const std::string camera_json =
      options.camera.empty()
          ? CameraJson(options.camera_model, options.camera_params)
          : "";
  std::optional<std::array<ImageCircle, 2>> given_circles;
  if (!options.circles.empty()) {
    std::array<ImageCircle, 2> circles;
    ParseImageCircles(options.circles, &circles);
    given_circles = circles;
  }

  const std::vector<FrameFiles> frames = ListFrames(options);
  CheckOutputsAreNew(frames, lens_names, options.output_path);
  const sphera::CameraPreset* preset =
      options.camera.empty() ? nullptr
                             : &sphera::FindCameraPreset(options.camera);
  // The generic preset knows no circles: they are found in the frames, and
  // each lens starts from the preset's lens on its own circle.
  const bool detect_preset_circles = preset && preset->any_two_to_one_size;
  std::optional<sphera::PresetResolution> resolution;
  if (preset && !detect_preset_circles) {
    const auto found = PresetCircles(*preset, frames);
    if (!found) {
      ScanFrames(frames, lens_names, given_circles, options.black_level);
      throw std::invalid_argument("no frame can be read");
    }
    given_circles = found->first;
    resolution = found->second;
    LOG(INFO) << "dual_fisheye_splitter: " << preset->name << " "
              << resolution->name << ": circles " << resolution->source;
  }
  const FrameScan scan =
      ScanFrames(frames, lens_names, given_circles, options.black_level);
  if (options.camera.empty() && !options.camera_model.empty()) {
    // The lenses' camera as the mapper will check it, on the lens images'
    // size (a focal length of 0, a principal point far off the image).
    Camera camera;
    camera.model_id = CameraModelNameToId(options.camera_model);
    camera.width = scan.lens_size.width;
    camera.height = scan.lens_size.height;
    camera.params = CameraParamsValues(options.camera_params);
    if (const std::string error = CameraParamsError(camera); !error.empty()) {
      throw std::invalid_argument(
          "--camera_params: " + error + " (for the " +
          std::to_string(camera.width) + "x" + std::to_string(camera.height) +
          " lens images)");
    }
  }
  std::array<ImageCircle, 2> circles;
  if (given_circles) {
    circles = *given_circles;
  } else {
    circles = CirclesFromDetections(
        scan, frames.size(), lens_names, options.black_level);
    CheckFrames(frames, circles, options.black_level);
  }
  for (int lens = 0; lens < 2; ++lens) {
    std::ostringstream origin;
    if (given_circles) {
      origin << (options.camera.empty() ? "given" : "of the preset");
    } else {
      origin << "detected (median of " << scan.detected[lens].size() << " of "
             << frames.size() << " frames, each within "
             << std::lround(
                    LargestDeviation(scan.detected[lens], circles[lens]))
             << " px of it)";
    }
    LOG(INFO) << "dual_fisheye_splitter: " << lens_names[lens]
              << ": image circle (cx, cy, r) = ("
              << ShortestDoubleText(circles[lens].cx) << ", "
              << ShortestDoubleText(circles[lens].cy) << ", "
              << ShortestDoubleText(circles[lens].r) << ") " << origin.str();
    // More than the edge's own uncertainty (1% of r): the circle moves.
    if (!given_circles &&
        LargestDeviation(scan.detected[lens], circles[lens]) >
            0.01 * circles[lens].r) {
      LOG(WARNING) << "dual_fisheye_splitter: " << lens_names[lens]
                   << "'s image circle differs between frames by more than "
                      "1% of its radius (a stabilised or cropped video, or "
                      "frames of two cameras?); the median is used for "
                      "every frame (--circles sets one)";
    }
  }

  std::string rig_config;
  if (preset) {
    if (detect_preset_circles) {
      resolution = sphera::PresetResolution{
          "detected",
          2 * scan.lens_size.width,
          scan.lens_size.height,
          {{circles[0].cx, circles[0].cy, circles[0].r},
           {circles[1].cx, circles[1].cy, circles[1].r}},
          "detected in the frames"};
    }
    rig_config = sphera::PresetRigConfigJson(
        *preset, *resolution, {lens_names[0], lens_names[1]},
        options.camera_model);
  } else {
    rig_config = RigConfigJson(lens_names, camera_json);
  }
  const std::array<RadialFalloff, 2> falloffs =
      options.flat_field ? EstimateFalloffs(frames, lens_names, circles,
                                            options.black_level)
                         : std::array<RadialFalloff, 2>();
  WriteOutputs(options, frames, lens_names, circles, falloffs,
               scan.lens_size, rig_config);
  size_t num_images = 0;
  for (const FrameFiles& frame : frames) {
    num_images += frame.SideBySide() ? 2
                                     : (frame.lens_files[0] ? 1 : 0) +
                                           (frame.lens_files[1] ? 1 : 0);
  }
  LOG(INFO) << "dual_fisheye_splitter: " << frames.size() << " raw frames -> "
            << num_images << " lens images and masks ("
            << SizeText(scan.lens_size) << ") in "
            << options.output_path.string() << "/images/{" << lens_names[0]
            << "," << lens_names[1] << "}";
}

}  // namespace colmap
