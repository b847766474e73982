// sphera_render: renders the synthetic SPHERA room through any camera model
// and writes images, depth maps and COLMAP text ground truth.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "synthetic/model_io.h"
#include "synthetic/rig.h"

namespace {

const char kUsage[] = R"(Usage: sphera_render --output DIR [options]

Renders the SPHERA synthetic room (4 x 4 x 3 m, +Y down, floor at y = 1.5)
and writes DIR/images/, DIR/depth/NAME.depth.bin, DIR/sparse_gt/{cameras,
images,points3D}.txt (COLMAP text, cam_from_world) and DIR/rig.txt.
DIR must not exist or be empty; it is written as DIR.tmp, then renamed.

Cameras (a rig file, or a layout):
  --rig FILE             lines 'NAME MODEL WIDTH HEIGHT PARAMS... | QW QX QY QZ TX TY TZ'
  --layout NAME          room9 (default: 9 cameras, 3x3 grid, 1 m spacing),
                         ring (16 outward-looking PINHOLE cameras, for stock COLMAP),
                         grid (N cameras, random headings)
  --num_cameras N        cameras of the ring/grid layout
  --model NAME           EQUIRECTANGULAR (default; ring: PINHOLE), PINHOLE, OPENCV,
                         EUCM, UNIFIED_OMNI, DOUBLE_SPHERE, ...
  --width W --height H   image size (default 2048x1024 equirect, 640x480 perspective,
                         1024x1024 fisheye)
  --camera_params LIST   model parameters, comma separated (default: per model)
A multi-lens camera moved along a path of frames (see synthetic/rig.h):
  --rig_preset NAME      dual_fisheye (two back-to-back 200 degree lenses, 3 cm
                         apart) or ring8 (8 outward 195 degree lenses on a 6 cm ring)
  --rig_sensors FILE     lines 'NAME MODEL W H PARAMS... | QW QX QY QZ TX TY TZ [MAX_ANGLE_DEG]'
                         (sensor_from_rig; the first lens is the reference)
  --frames N             frames on a loop through the room (default 10)
  --lens_size S          pixels of a preset's square lens images
  --raw                  also write DIR/raw/: both lenses side by side (two lenses)
  --stitched             also write DIR/stitched/: the equirectangular panorama a
                         stitcher makes of every frame (lenses assumed to share a centre)
  --stitched_width W     panorama width (default 2048)
  --stitch_band_deg D    blend band across the seam (default 10)
  --stitch_distance M    stitching distance in metres (default 0: at infinity)
Scene and rendering:
  --seed S               texture and layout seed (default 0)
  --texture KIND         procedural (default) or checker
  --checker_size M       checker square side in metres (default 0.25)
  --no_boxes             empty room without furniture
  --supersample K        K x K rays per pixel (default 3)
  --points N             write up to N ground-truth 3D points with observations
  --format jpg|png       image format for generated names (default jpg)
  --num_threads T        0 = all cores (default)
Sensor effects (see synthetic/sensor_effects.h; all off by default; they change
pixels only, never the ground truth; in a rig every lens meters on its own):
  --realistic            a consumer 360-camera preset: --circle_radius 1.05
                         --housing 55 --surround 14 --vignetting 0.35 --flare 40
                         --exposure_jitter 0.25 --white_balance_jitter 0.05
                         --noise_sigma 2 --jpeg_quality 90; the options below
                         override single values
  --circle_radius R      image circle radius in half frame heights (0: none; > 1
                         crops it at the top and bottom), centred on the frame
                         or on a rig lens's own circle
  --housing L            brightness (DN) of the lens housing ring outside the circle
  --surround L           brightness (DN) beyond the housing
  --vignetting V         fraction of light lost at the circle's rim, in [0, 1)
  --flare L              peak brightness (DN) of a flare blob and streak per image
  --exposure_jitter S    per-lens exposure spread in stops (standard deviation)
  --white_balance_jitter S  per-lens red and blue gain spread in stops
  --noise_sigma S        Gaussian read noise in DN (default 0)
  --jpeg_quality Q       JPEG quality 1..100 (default 95; needs --format jpg)
  --effects_seed S       seed of the effects' randomness (default: --seed)
  --write_masks          write DIR/masks/NAME.png (255 = sees the scene) for every
                         image; images with an image circle always get one
)";

int Fail(const std::string& message) {
  std::cerr << "sphera_render: error: " << message << "\n";
  return 1;
}

bool ParseInt(const std::string& text, long long* value) {
  try {
    size_t used = 0;
    *value = std::stoll(text, &used);
    return used == text.size();
  } catch (const std::exception&) {
    return false;
  }
}

bool ParseDouble(const std::string& text, double* value) {
  try {
    size_t used = 0;
    *value = std::stod(text, &used);
    return used == text.size();
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sphera::synthetic;
  std::map<std::string, std::string> args;
  std::map<std::string, bool> switches = {{"--no_boxes", false},   {"--raw", false},
                                          {"--stitched", false},   {"--realistic", false},
                                          {"--write_masks", false}};
  const std::vector<std::string> value_flags = {
      "--output", "--layout", "--num_cameras", "--model", "--width", "--height",
      "--camera_params", "--rig", "--seed", "--texture", "--checker_size", "--supersample",
      "--noise_sigma", "--points", "--format", "--num_threads", "--rig_preset", "--rig_sensors",
      "--frames", "--lens_size", "--stitched_width", "--stitch_band_deg", "--stitch_distance",
      "--circle_radius", "--housing", "--surround", "--vignetting", "--flare",
      "--exposure_jitter", "--white_balance_jitter", "--jpeg_quality", "--effects_seed"};
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--help" || flag == "-h") {
      std::cout << kUsage;
      return 0;
    }
    if (switches.count(flag)) {
      switches[flag] = true;
      continue;
    }
    bool known = false;
    for (const std::string& f : value_flags) known = known || f == flag;
    if (!known) return Fail("unknown option '" + flag + "' (see --help)");
    if (i + 1 >= argc) return Fail("option " + flag + " needs a value");
    args[flag] = argv[++i];
  }
  auto get_int = [&](const std::string& flag, long long fallback, long long min_value,
                     long long max_value, long long* value) {
    *value = fallback;
    if (!args.count(flag)) return true;
    if (!ParseInt(args[flag], value) || *value < min_value || *value > max_value) {
      std::cerr << "sphera_render: error: " << flag << " must be an integer in [" << min_value
                << ", " << max_value << "] (got '" << args[flag] << "')\n";
      return false;
    }
    return true;
  };
  auto get_double = [&](const std::string& flag, double fallback, double* value) {
    *value = fallback;
    if (!args.count(flag)) return true;
    if (!ParseDouble(args[flag], value)) {
      std::cerr << "sphera_render: error: " << flag << " must be a number (got '" << args[flag]
                << "')\n";
      return false;
    }
    return true;
  };

  const bool no_boxes = switches["--no_boxes"], raw = switches["--raw"],
             stitched = switches["--stitched"];
  if (!args.count("--output")) return Fail("--output DIR is required (see --help)");
  long long seed, num_cameras, width, height, supersample, points, num_threads, num_frames,
      lens_size, stitched_width;
  double checker_size, stitch_band, stitch_distance;
  if (!get_int("--seed", 0, 0, (1LL << 62), &seed) ||
      !get_int("--num_cameras", 0, 1, 10000, &num_cameras) ||
      !get_int("--width", 0, 1, 65536, &width) || !get_int("--height", 0, 1, 65536, &height) ||
      !get_int("--supersample", 3, 1, 16, &supersample) ||
      !get_int("--points", 0, 0, 100000000, &points) ||
      !get_int("--num_threads", 0, 0, 1024, &num_threads) ||
      !get_double("--checker_size", 0.25, &checker_size) ||
      !get_int("--frames", 10, 1, 10000, &num_frames) ||
      !get_int("--lens_size", 0, 16, 65536, &lens_size) ||
      !get_int("--stitched_width", 2048, 16, 65536, &stitched_width) ||
      !get_double("--stitch_band_deg", 10, &stitch_band) ||
      !get_double("--stitch_distance", 0, &stitch_distance)) {
    return 1;
  }
  const std::string format = args.count("--format") ? args["--format"] : "jpg";
  if (format != "jpg" && format != "png") return Fail("--format must be jpg or png");
  const std::string extension = "." + format;

  // Sensor effects: the preset, then single values; the field names are the
  // option names, so Check()'s message names the option.
  SensorEffects effects = switches["--realistic"] ? SensorEffects::Realistic() : SensorEffects();
  for (const auto& [flag, field] : std::vector<std::pair<std::string, double*>>{
           {"--circle_radius", &effects.circle_radius},
           {"--housing", &effects.housing},
           {"--surround", &effects.surround},
           {"--vignetting", &effects.vignetting},
           {"--flare", &effects.flare},
           {"--exposure_jitter", &effects.exposure_jitter},
           {"--white_balance_jitter", &effects.white_balance_jitter},
           {"--noise_sigma", &effects.noise_sigma}}) {
    if (!get_double(flag, *field, field)) return 1;
  }
  long long jpeg_quality, effects_seed;
  if (!get_int("--jpeg_quality", effects.jpeg_quality, 1, 100, &jpeg_quality) ||
      !get_int("--effects_seed", seed, 0, (1LL << 62), &effects_seed)) {
    return 1;
  }
  if (args.count("--jpeg_quality") && format != "jpg") {
    return Fail("--jpeg_quality needs --format jpg");
  }
  effects.jpeg_quality = static_cast<int>(jpeg_quality);
  effects.seed = static_cast<uint64_t>(effects_seed);
  const std::string effects_error = effects.Check();
  if (!effects_error.empty()) return Fail("--" + effects_error);

  SceneOptions scene_options;
  scene_options.seed = static_cast<uint64_t>(seed);
  scene_options.with_boxes = !no_boxes;
  scene_options.checker_size_m = checker_size;
  const std::string texture = args.count("--texture") ? args["--texture"] : "procedural";
  if (texture == "checker") {
    scene_options.texture = TextureKind::kChecker;
  } else if (texture != "procedural") {
    return Fail("--texture must be procedural or checker (got '" + texture + "')");
  }
  const std::string scene_error = scene_options.Check();
  if (!scene_error.empty()) return Fail(scene_error);
  const Scene scene(scene_options);

  DatasetOptions options;
  options.render.supersample = static_cast<int>(supersample);
  options.render.num_threads = static_cast<int>(num_threads);
  options.effects = effects;
  options.write_masks = switches["--write_masks"];
  options.num_points = static_cast<int>(points);
  options.points_seed = static_cast<uint64_t>(seed);
  const auto start = std::chrono::steady_clock::now();

  const bool is_rig = args.count("--rig_preset") || args.count("--rig_sensors");
  for (const char* flag : {"--frames", "--lens_size", "--stitched_width", "--stitch_band_deg",
                           "--stitch_distance"}) {
    if (!is_rig && args.count(flag)) {
      return Fail(std::string(flag) + " needs --rig_preset or --rig_sensors");
    }
  }
  if (!is_rig && (raw || stitched)) return Fail("--raw and --stitched need a rig");
  if (is_rig) {
    if (args.count("--rig_preset") && args.count("--rig_sensors")) {
      return Fail("give --rig_preset or --rig_sensors, not both");
    }
    for (const char* flag : {"--rig", "--layout", "--num_cameras", "--model", "--width",
                             "--height", "--camera_params"}) {
      if (args.count(flag)) return Fail(std::string(flag) + " cannot be combined with a rig");
    }
    if (args.count("--lens_size") && args.count("--rig_sensors")) {
      return Fail("--lens_size applies to --rig_preset only");
    }
    if (!(stitch_band > 0 && stitch_band <= 90)) return Fail("--stitch_band_deg must be in (0, 90]");
    if (!(stitch_distance >= 0 && std::isfinite(stitch_distance))) {
      return Fail("--stitch_distance must be >= 0");
    }
    std::vector<RigSensor> sensors;
    const std::string rig_error =
        args.count("--rig_preset")
            ? MakeRigPreset(args["--rig_preset"], static_cast<int>(lens_size), &sensors)
            : ReadRigSensors(args["--rig_sensors"], &sensors);
    if (!rig_error.empty()) return Fail(rig_error);
    RigDatasetOptions rig_options;
    rig_options.dataset = options;
    rig_options.image_extension = extension;
    rig_options.raw = raw;
    rig_options.stitched = stitched;
    rig_options.stitched_width = static_cast<int>(stitched_width);
    rig_options.stitch_band_deg = stitch_band;
    rig_options.stitch_distance_m = stitch_distance;
    const std::string error =
        WriteRigDataset(args["--output"], scene,
                        sensors, MakeFramePath(static_cast<int>(num_frames),
                                               static_cast<uint64_t>(seed)),
                        rig_options, &std::cout);
    if (!error.empty()) return Fail(error);
    std::cout << "total "
              << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
              << " s\n";
    return 0;
  }

  std::vector<VirtualCamera> cameras;
  if (args.count("--rig")) {
    for (const char* flag : {"--layout", "--num_cameras", "--model", "--width", "--height",
                             "--camera_params"}) {
      if (args.count(flag)) return Fail(std::string(flag) + " cannot be combined with --rig");
    }
    const std::string error = ReadRigFile(args["--rig"], extension, &cameras);
    if (!error.empty()) return Fail(error);
  } else {
    LayoutOptions layout;
    if (args.count("--layout")) layout.layout = args["--layout"];
    layout.num_cameras = static_cast<int>(num_cameras);
    if (args.count("--model")) layout.model_name = args["--model"];
    layout.width = static_cast<int>(width);
    layout.height = static_cast<int>(height);
    if (args.count("--camera_params") &&
        !ParseParamList(args["--camera_params"], &layout.params)) {
      return Fail("--camera_params: malformed list '" + args["--camera_params"] + "'");
    }
    layout.seed = static_cast<uint64_t>(seed);
    layout.image_extension = extension;
    const std::string error = MakeLayout(layout, &cameras);
    if (!error.empty()) return Fail(error);
  }

  const std::string error = WriteDataset(args["--output"], scene, cameras, options, &std::cout);
  if (!error.empty()) return Fail(error);
  std::cout << "total "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
            << " s\n";
  return 0;
}
