#include "synthetic/sensor_effects.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "synthetic/model_io.h"
#include "synthetic/rig.h"

namespace sphera {
namespace synthetic {
namespace {

namespace fs = std::filesystem;

fs::path FreshPath(const std::string& name) {
  const fs::path path =
      fs::path(::testing::TempDir()) / ("sphera_fx_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(path);
  fs::remove_all(path.string() + ".tmp");
  return path;
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

// Only the frame size and the image circle of a camera matter to the sensor.
VirtualCamera FrameOnly(int width, int height) {
  return MakeCamera("t.png", "PINHOLE", width, height,
                    {width / 2.0, width / 2.0, width / 2.0, height / 2.0},
                    Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
}

cv::Mat ConstantRadiance(int width, int height, double level) {
  return cv::Mat(height, width, CV_64FC3, cv::Scalar(level, level, level));
}

cv::Mat RandomRadiance(int width, int height, uint64_t seed) {
  cv::Mat radiance(height, width, CV_64FC3);
  cv::RNG rng(seed);
  rng.fill(radiance, cv::RNG::UNIFORM, 30.0, 220.0);
  return radiance;
}

// Per-channel mean (B, G, R) over the pixels whose centre is at a distance
// in [min_px, max_px] from `centre`; the pixel count in `count`.
cv::Vec3d MeanInAnnulus(const cv::Mat& image, const Eigen::Vector2d& centre, double min_px,
                        double max_px, int* count) {
  cv::Vec3d sum(0, 0, 0);
  *count = 0;
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      const double r = (Eigen::Vector2d(col + 0.5, row + 0.5) - centre).norm();
      if (r < min_px || r > max_px) continue;
      const cv::Vec3b& pixel = image.at<cv::Vec3b>(row, col);
      for (int c = 0; c < 3; ++c) sum[c] += pixel[c];
      ++*count;
    }
  }
  return *count > 0 ? sum / *count : sum;
}

TEST(SensorEffects, OffGivesThePlainRenderersPixels) {
  const Scene scene(SceneOptions{});
  RenderOptions render;
  render.supersample = 2;
  VirtualCamera fisheye =
      MakeCamera("f.png", "EUCM", 80, 64, {22, 22, 40, 32, 0.6, 1.0},
                 Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.3, 0.1, -0.2));
  fisheye.image_circle = Eigen::Vector3d(40, 32, 30);  // a lens with its own circle
  const VirtualCamera pinhole =
      MakeCamera("p.png", "PINHOLE", 72, 48, {36, 36, 36, 24},
                 Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                 Eigen::Vector3d(-0.4, 0, 0.3));
  for (const VirtualCamera& camera : {fisheye, pinhole}) {
    const RenderedImage rendered = Render(scene, camera, render);
    const cv::Mat image = ApplySensorEffects(rendered.radiance, camera, SensorEffects(), 3, 7);
    EXPECT_EQ(cv::norm(image, rendered.image, cv::NORM_INF), 0) << camera.name;
    // Any one effect changes them.
    SensorEffects noisy;
    noisy.noise_sigma = 1;
    EXPECT_GT(cv::norm(ApplySensorEffects(rendered.radiance, camera, noisy, 3, 7), rendered.image,
                       cv::NORM_L1),
              0)
        << camera.name;
  }
}

TEST(SensorEffects, OutsideTheCircleIsSurroundNotScene) {
  const int width = 120, height = 80;
  const VirtualCamera camera = FrameOnly(width, height);
  SensorEffects effects;
  effects.circle_radius = 1.05;  // 42 px: cropped at the top and bottom
  effects.surround = 30;
  effects.seed = 5;
  const double radius = 1.05 * height / 2;
  const Eigen::Vector3d circle = LensCircle(camera, effects);
  EXPECT_NEAR(circle.x(), width / 2.0, 1e-12);
  EXPECT_NEAR(circle.y(), height / 2.0, 1e-12);
  EXPECT_NEAR(circle.z(), radius, 1e-12);

  const cv::Mat a = ApplySensorEffects(RandomRadiance(width, height, 1), camera, effects, 0, 0);
  const cv::Mat b = ApplySensorEffects(RandomRadiance(width, height, 2), camera, effects, 0, 0);
  const cv::Mat mask = ValidPixelMask(camera, effects);
  int outside = 0, inside = 0, inside_differs = 0;
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const double r = std::hypot(col + 0.5 - width / 2.0, row + 0.5 - height / 2.0);
      EXPECT_EQ(mask.at<uint8_t>(row, col), r <= radius ? 255 : 0) << col << ", " << row;
      if (r > radius + 1) {
        // The surround does not depend on the scene and is not black.
        ++outside;
        ASSERT_EQ(a.at<cv::Vec3b>(row, col), b.at<cv::Vec3b>(row, col)) << col << ", " << row;
        const cv::Vec3b& pixel = a.at<cv::Vec3b>(row, col);
        EXPECT_NEAR((pixel[0] + pixel[1] + pixel[2]) / 3.0, effects.surround,
                    0.5 * effects.surround)
            << col << ", " << row;
      } else if (r < radius - 1) {
        ++inside;
        inside_differs += a.at<cv::Vec3b>(row, col) != b.at<cv::Vec3b>(row, col);
      }
    }
  }
  EXPECT_GT(outside, 100);
  EXPECT_GT(inside_differs, 0.9 * inside);
  // Cropped: the circle reaches the top and bottom rows in the middle, not
  // the corners.
  EXPECT_EQ(mask.at<uint8_t>(0, width / 2), 255);
  EXPECT_EQ(mask.at<uint8_t>(height - 1, width / 2), 255);
  EXPECT_EQ(mask.at<uint8_t>(0, 0), 0);
  EXPECT_EQ(mask.at<uint8_t>(0, width - 1), 0);
}

TEST(SensorEffects, HousingRingIsAboveBlackWhereSet) {
  const int size = 200;
  const VirtualCamera camera = FrameOnly(size, size);
  SensorEffects effects;
  effects.circle_radius = 0.7;  // 70 px
  effects.housing_width = 0.2;  // 14 px ring
  const double radius = 70, ring = 14;
  const Eigen::Vector2d centre(size / 2.0, size / 2.0);
  const cv::Mat radiance = ConstantRadiance(size, size, 150);
  int count = 0;
  // Without a housing the ring is black.
  cv::Vec3d mean =
      MeanInAnnulus(ApplySensorEffects(radiance, camera, effects, 0, 0), centre, radius + 1,
                    radius + ring - 1, &count);
  ASSERT_GT(count, 500);
  EXPECT_EQ(mean, cv::Vec3d(0, 0, 0));
  effects.housing = 60;
  const cv::Mat image = ApplySensorEffects(radiance, camera, effects, 0, 0);
  mean = MeanInAnnulus(image, centre, radius + 1, radius + ring - 1, &count);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(mean[c], 0.7 * effects.housing) << c;
    EXPECT_LT(mean[c], 1.3 * effects.housing) << c;
  }
  // Beyond the ring (no surround set) it is black again; inside it is scene.
  mean = MeanInAnnulus(image, centre, radius + ring + 2, 1e9, &count);
  ASSERT_GT(count, 1000);
  EXPECT_EQ(mean, cv::Vec3d(0, 0, 0));
  mean = MeanInAnnulus(image, centre, 0, radius - 1, &count);
  EXPECT_EQ(mean, cv::Vec3d(150, 150, 150));
}

TEST(SensorEffects, VignettingLosesTheConfiguredFractionTowardsTheRim) {
  const int size = 200;
  const VirtualCamera camera = FrameOnly(size, size);
  const double level = 200;
  const cv::Mat radiance = ConstantRadiance(size, size, level);
  const Eigen::Vector2d centre(size / 2.0, size / 2.0);
  for (const double circle_radius : {0.9, 0.0}) {
    SensorEffects effects;
    effects.circle_radius = circle_radius;
    effects.vignetting = 0.4;
    const cv::Mat image = ApplySensorEffects(radiance, camera, effects, 0, 0);
    // The rim: the circle's radius, or the frame's half-diagonal.
    const double rim = circle_radius > 0 ? circle_radius * size / 2 : std::hypot(size, size) / 2;
    int count = 0;
    const cv::Vec3d middle = MeanInAnnulus(image, centre, 0, 2, &count);
    EXPECT_NEAR(middle[1], level, 0.6) << circle_radius;
    for (const double rho : {0.5, 0.8, 0.97}) {
      const cv::Vec3d mean = MeanInAnnulus(image, centre, rho * rim - 0.5, rho * rim + 0.5, &count);
      ASSERT_GT(count, 10);
      const double expected =
          level * ((1 - effects.vignetting) + effects.vignetting * std::pow(1 - rho * rho, 2));
      EXPECT_NEAR(mean[1], expected, 0.02 * level) << circle_radius << " " << rho;
    }
  }
}

TEST(SensorEffects, ExposureAndWhiteBalanceDifferPerLensAsDrawn) {
  const VirtualCamera camera = FrameOnly(40, 30);
  SensorEffects effects;
  effects.exposure_jitter = 0.5;
  effects.white_balance_jitter = 0.1;
  effects.seed = 9;
  const double level = 80;
  const cv::Mat radiance = ConstantRadiance(40, 30, level);
  std::vector<double> gains;
  for (int lens = 0; lens < 4; ++lens) {
    const LensResponse response = DrawLensResponse(effects, lens);
    gains.push_back(response.exposure_gain);
    EXPECT_EQ(response.white_balance_rgb.y(), 1);
    const cv::Mat image = ApplySensorEffects(radiance, camera, effects, lens, 0);
    const cv::Scalar mean = cv::mean(image);
    // BGR in the image, RGB in the response.
    for (int c = 0; c < 3; ++c) {
      const double expected =
          std::min(255.0, level * response.exposure_gain * response.white_balance_rgb[2 - c]);
      EXPECT_NEAR(mean[c], expected, 0.5) << "lens " << lens << " channel " << c;
    }
  }
  // With a 0.5-stop spread four lenses do not share one exposure.
  EXPECT_GT(*std::max_element(gains.begin(), gains.end()) /
                *std::min_element(gains.begin(), gains.end()),
            1.05);
  // Without jitter every lens has gain 1.
  EXPECT_EQ(DrawLensResponse(SensorEffects(), 3).exposure_gain, 1);
}

TEST(SensorEffects, NoiseHasTheConfiguredSigmaAndFollowsTheSeed) {
  const int size = 160;
  const VirtualCamera camera = FrameOnly(size, size);
  const cv::Mat radiance = ConstantRadiance(size, size, 100);
  for (const double sigma : {1.5, 4.0}) {
    SensorEffects effects;
    effects.noise_sigma = sigma;
    effects.seed = 3;
    const cv::Mat image = ApplySensorEffects(radiance, camera, effects, 0, 0);
    cv::Scalar mean, stddev;
    cv::meanStdDev(image, mean, stddev);
    // Rounding adds 1/12 DN^2 of variance.
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(stddev[c], std::sqrt(sigma * sigma + 1.0 / 12), 0.05 * sigma) << sigma;
      EXPECT_NEAR(mean[c], 100, 0.2) << sigma;
    }
  }
}

TEST(SensorEffects, SameSeedSameBytesOtherSeedOtherBytes) {
  const VirtualCamera camera = FrameOnly(96, 64);
  const cv::Mat radiance = RandomRadiance(96, 64, 4);
  SensorEffects effects = SensorEffects::Realistic();
  effects.seed = 21;
  const cv::Mat a = ApplySensorEffects(radiance, camera, effects, 1, 5);
  const cv::Mat b = ApplySensorEffects(radiance, camera, effects, 1, 5);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
  // Another image of the same lens: other flare and noise.
  EXPECT_GT(cv::norm(a, ApplySensorEffects(radiance, camera, effects, 1, 6), cv::NORM_L1), 0);
  effects.seed = 22;
  EXPECT_GT(cv::norm(a, ApplySensorEffects(radiance, camera, effects, 1, 5), cv::NORM_L1), 0);
}

TEST(SensorEffects, CheckNamesTheField) {
  EXPECT_EQ(SensorEffects().Check(), "");
  EXPECT_EQ(SensorEffects::Realistic().Check(), "");
  const std::vector<std::pair<std::string, std::function<void(SensorEffects*)>>> bad = {
      {"circle_radius", [](SensorEffects* e) { e->circle_radius = -1; }},
      {"housing", [](SensorEffects* e) { e->housing = 300; }},
      {"vignetting", [](SensorEffects* e) { e->vignetting = 1; }},
      {"flare", [](SensorEffects* e) { e->flare = NAN; }},
      {"exposure_jitter", [](SensorEffects* e) { e->exposure_jitter = 4; }},
      {"noise_sigma", [](SensorEffects* e) { e->noise_sigma = -0.1; }},
      {"jpeg_quality", [](SensorEffects* e) { e->jpeg_quality = 101; }},
  };
  for (const auto& [field, spoil] : bad) {
    SensorEffects effects;
    spoil(&effects);
    EXPECT_EQ(effects.Check().rfind(field + " must be", 0), 0u) << effects.Check();
  }
}

// sphera_render with `args`; its stderr in `stderr_text`. Returns the exit code.
int RunRender(const std::string& args, std::string* stderr_text = nullptr) {
  const fs::path err = FreshPath("stderr");
  const std::string command =
      std::string(SPHERA_RENDER_EXE) + " " + args + " >/dev/null 2>" + err.string();
  const int status = std::system(command.c_str());
  if (stderr_text) *stderr_text = ReadBytes(err);
  fs::remove(err);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(SensorEffectsProgram, RefusesBadValuesNamingTheOption) {
  const fs::path dir = FreshPath("bad");
  const std::string base = "--output " + dir.string() + " --layout grid --num_cameras 2 "
                           "--width 32 --height 16 --supersample 1 ";
  for (const std::string& option :
       {"--circle_radius -1", "--circle_radius abc", "--housing 256", "--vignetting 1",
        "--exposure_jitter 9", "--noise_sigma -2", "--jpeg_quality 0", "--jpeg_quality 101",
        "--flare nan", "--effects_seed -3"}) {
    std::string message;
    EXPECT_EQ(RunRender(base + option, &message), 1) << option;
    const std::string flag = option.substr(0, option.find(' '));
    EXPECT_NE(message.find(flag), std::string::npos) << option << ": " << message;
  }
  std::string message;
  EXPECT_EQ(RunRender(base + "--format png --jpeg_quality 80", &message), 1);
  EXPECT_NE(message.find("--jpeg_quality"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir));
}

TEST(SensorEffectsProgram, RealisticChangesPixelsNotGroundTruth) {
  const fs::path plain = FreshPath("plain"), real = FreshPath("real");
  const std::string scene = " --layout grid --num_cameras 2 --model EUCM --width 64 --height 48 "
                            "--supersample 1 --points 20 --format png";
  ASSERT_EQ(RunRender("--output " + plain.string() + scene), 0);
  ASSERT_EQ(RunRender("--output " + real.string() + scene + " --realistic --write_masks"), 0);
  for (const char* file : {"sparse_gt/cameras.txt", "sparse_gt/images.txt",
                           "sparse_gt/points3D.txt", "rig.txt"}) {
    const std::string text = ReadBytes(plain / file);
    EXPECT_FALSE(text.empty()) << file;
    EXPECT_EQ(text, ReadBytes(real / file)) << file;
  }
  for (const char* name : {"cam000.png", "cam001.png"}) {
    const cv::Mat a = cv::imread((plain / "images" / name).string());
    const cv::Mat b = cv::imread((real / "images" / name).string());
    ASSERT_FALSE(a.empty());
    ASSERT_EQ(a.size(), b.size());
    EXPECT_GT(cv::norm(a, b, cv::NORM_L1) / a.total(), 1.0) << name;
    // The plain run has no circle and writes no masks; the realistic one
    // writes the cropped circle's mask.
    EXPECT_FALSE(fs::exists(plain / "masks" / (std::string(name) + ".png")));
    const cv::Mat mask =
        cv::imread((real / "masks" / (std::string(name) + ".png")).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_EQ(mask.size(), a.size()) << name;
    EXPECT_EQ(mask.at<uint8_t>(0, 32), 255);
    EXPECT_EQ(mask.at<uint8_t>(0, 0), 0);
  }
  fs::remove_all(plain);
  fs::remove_all(real);
}

TEST(SensorEffectsProgram, JpegQualityOptionWritesJpegOfThatQuality) {
  const fs::path low = FreshPath("q20"), high = FreshPath("q98");
  const std::string scene = " --layout grid --num_cameras 1 --width 96 --height 48 "
                            "--supersample 1";
  ASSERT_EQ(RunRender("--output " + low.string() + scene + " --jpeg_quality 20"), 0);
  ASSERT_EQ(RunRender("--output " + high.string() + scene + " --jpeg_quality 98"), 0);
  const std::string low_bytes = ReadBytes(low / "images/cam000.jpg");
  const std::string high_bytes = ReadBytes(high / "images/cam000.jpg");
  ASSERT_GT(low_bytes.size(), 3u);
  // JPEG's start-of-image marker.
  EXPECT_EQ(low_bytes.substr(0, 3), std::string("\xff\xd8\xff"));
  EXPECT_EQ(high_bytes.substr(0, 3), std::string("\xff\xd8\xff"));
  EXPECT_LT(low_bytes.size(), high_bytes.size());
  EXPECT_EQ(ImageWriteParams("x.jpg", 20), (std::vector<int>{cv::IMWRITE_JPEG_QUALITY, 20}));
  EXPECT_EQ(ImageWriteParams("x.jpg", 0), (std::vector<int>{cv::IMWRITE_JPEG_QUALITY, 95}));
  fs::remove_all(low);
  fs::remove_all(high);
}

TEST(SensorEffectsProgram, EveryRigLensHasItsOwnExposure) {
  const fs::path plain = FreshPath("rig_plain"), jittered = FreshPath("rig_jitter");
  const std::string rig = " --rig_preset dual_fisheye --lens_size 48 --frames 1 --supersample 1 "
                          "--format png --seed 2";
  ASSERT_EQ(RunRender("--output " + plain.string() + rig), 0);
  ASSERT_EQ(RunRender("--output " + jittered.string() + rig + " --exposure_jitter 0.6"), 0);
  SensorEffects effects;
  effects.exposure_jitter = 0.6;
  effects.seed = 2;  // --effects_seed defaults to --seed
  std::vector<double> ratios;
  for (const int lens : {0, 1}) {
    const std::string name = "lens" + std::to_string(lens) + "/frame000.png";
    const cv::Mat a = cv::imread((plain / "images" / name).string());
    const cv::Mat b = cv::imread((jittered / "images" / name).string());
    const cv::Mat mask =
        cv::imread((plain / "masks" / (name + ".png")).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(a.empty() || b.empty() || mask.empty()) << name;
    // Unclipped pixels inside the lens circle.
    double sum_a = 0, sum_b = 0;
    for (int row = 0; row < a.rows; ++row) {
      for (int col = 0; col < a.cols; ++col) {
        if (!mask.at<uint8_t>(row, col)) continue;
        const cv::Vec3b pa = a.at<cv::Vec3b>(row, col), pb = b.at<cv::Vec3b>(row, col);
        if (std::max({pb[0], pb[1], pb[2]}) == 255) continue;
        sum_a += pa[0] + pa[1] + pa[2];
        sum_b += pb[0] + pb[1] + pb[2];
      }
    }
    ASSERT_GT(sum_a, 0) << name;
    ratios.push_back(sum_b / sum_a);
    EXPECT_NEAR(sum_b / sum_a, DrawLensResponse(effects, lens).exposure_gain, 0.02) << name;
  }
  EXPECT_GT(std::abs(ratios[0] - ratios[1]), 0.05);
  fs::remove_all(plain);
  fs::remove_all(jittered);
}

}  // namespace
}  // namespace synthetic
}  // namespace sphera
