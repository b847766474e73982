// The synthetic room of the SPHERA paper: a 4 x 4 x 3 m box with flat walls,
// floor and ceiling, plus a few axis-aligned boxes so that depth varies.
//
// World frame (metres), chosen so that a camera with identity rotation is
// upright and looks at a wall, in COLMAP's camera convention (x right, y down,
// z forward):
//   x in [-2, 2]      horizontal
//   z in [-2, 2]      horizontal
//   y in [-1.5, 1.5]  vertical, +Y points DOWN (-Y is up)
// The floor is the plane y = +1.5, the ceiling y = -1.5, so y = 0 is 1.5 m
// above the floor (the paper's camera height).
//
// Every surface is an axis-aligned rectangle facing free space. Its texture is
// a function of the 3D surface point only (through per-face 2D coordinates),
// so every view of a surface point sees the same colour.
#ifndef SPHERA_SYNTHETIC_SCENE_H_
#define SPHERA_SYNTHETIC_SCENE_H_

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace sphera {
namespace synthetic {

constexpr double kRoomHalfX = 2.0;
constexpr double kRoomHalfY = 1.5;
constexpr double kRoomHalfZ = 2.0;

enum class TextureKind {
  // Multi-scale value noise blended with random coloured shapes: SIFT-rich,
  // non-repeating, deterministic from the seed.
  kProcedural,
  // Black/white checkerboard of square size `checker_size_m` in every face's
  // 2D coordinates; corners at integer multiples of the square size. For tests.
  kChecker,
};

struct SceneOptions {
  // Seed of the procedural texture (same seed, same room).
  uint64_t seed = 0;
  // Add the furniture boxes (false: an empty room of six faces).
  bool with_boxes = true;
  TextureKind texture = TextureKind::kProcedural;
  // Side of a checker square in metres (kChecker only).
  double checker_size_m = 0.25;

  // Empty string if valid, else a message naming the bad option.
  std::string Check() const;
};

// An axis-aligned rectangle facing free space. Its plane is
// x[axis] = offset; its normal is sign * e_axis; it spans [min_uv, max_uv] in
// the face coordinates (u, v) = (x[(axis+1)%3], x[(axis+2)%3]).
struct Face {
  int axis = 0;
  double offset = 0;
  int sign = 1;
  Eigen::Vector2d min_uv = Eigen::Vector2d::Zero();
  Eigen::Vector2d max_uv = Eigen::Vector2d::Zero();

  double Area() const;
  // Face coordinates of a point on the face plane.
  Eigen::Vector2d UV(const Eigen::Vector3d& point) const;
  Eigen::Vector3d PointFromUV(const Eigen::Vector2d& uv) const;
};

struct AlignedBox {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
};

struct RayHit {
  double range = 0;  // distance along the unit ray, metres
  int face_id = -1;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

class Scene {
 public:
  explicit Scene(const SceneOptions& options = SceneOptions());

  const SceneOptions& Options() const { return options_; }
  const std::vector<Face>& Faces() const { return faces_; }

  // Nearest front-facing surface along origin + t * direction, t > 0.
  // `direction` must be unit length so that `range` is metric.
  bool CastRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
               RayHit* hit) const;

  // Linear RGB-ish colour in [0, 1] of a surface point on face `face_id`.
  Eigen::Vector3f Colour(int face_id, const Eigen::Vector3d& point) const;

  // True if `point` is strictly inside the room and outside every box, i.e. a
  // valid camera centre.
  bool IsFreeSpace(const Eigen::Vector3d& point) const;

  // A uniformly random point on the union of all faces (by area).
  RayHit SampleSurfacePoint(std::mt19937_64* rng) const;

 private:
  void AddFace(int axis, double offset, int sign, const Eigen::Vector2d& min_uv,
               const Eigen::Vector2d& max_uv);
  void AddBox(const AlignedBox& box);
  Eigen::Vector3f ProceduralColour(int face_id, const Eigen::Vector2d& uv) const;

  // One octave of a face's fractal noise: its hash key (after the hash's
  // first round), rotation, shift, frequency and amplitude.
  struct NoiseOctave {
    uint64_t key_round = 0;
    double cos = 1, sin = 0, shift_x = 0, shift_y = 0;
    double frequency = 0, amplitude = 0;
  };
  struct Noise {
    std::vector<NoiseOctave> octaves;
    double norm = 0;  // the sum of the amplitudes
  };
  // What the procedural texture of a face draws from the seed and the face
  // alone, computed once per face: the texture is most of a render's time.
  struct FaceTexture {
    Noise detail;
    std::array<uint64_t, 3> shape_keys{};
    std::array<Noise, 3> tint;
  };
  void PrepareTextures();

  SceneOptions options_;
  std::vector<Face> faces_;
  std::vector<FaceTexture> textures_;
  std::vector<AlignedBox> boxes_;
  std::vector<double> cumulative_area_;
};

}  // namespace synthetic
}  // namespace sphera

#endif  // SPHERA_SYNTHETIC_SCENE_H_
