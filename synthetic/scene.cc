#include "synthetic/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace sphera {
namespace synthetic {
namespace {

// Tolerance of the point-in-rectangle test, so that rays through an edge
// shared by two faces never slip through the gap.
constexpr double kEdgeEpsilon = 1e-9;
constexpr double kMinRange = 1e-9;

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

uint64_t Hash(uint64_t a, uint64_t b, uint64_t c = 0, uint64_t d = 0,
              uint64_t e = 0) {
  uint64_t h = SplitMix64(a);
  h = SplitMix64(h ^ b);
  h = SplitMix64(h ^ c);
  h = SplitMix64(h ^ d);
  return SplitMix64(h ^ e);
}

// The last three rounds of Hash(a, b, c), whose d and e are zero:
// Hash(a, b, c) = HashRest3(SplitMix64(SplitMix64(a) ^ b) ^ c), so that
// hashes sharing a or (a, b) share their first rounds.
uint64_t HashRest3(uint64_t x) { return SplitMix64(SplitMix64(SplitMix64(x))); }

// Uniform in [0, 1) from the top 53 bits.
double UnitFromHash(uint64_t h) { return (h >> 11) * (1.0 / 9007199254740992.0); }

double Quintic(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }

// Value noise in [0, 1] on the unit integer lattice, the lattice's values
// Hash(key, i, j) (key_round = SplitMix64(key)).
double ValueNoise(uint64_t key_round, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int64_t ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  const double tx = Quintic(x - fx), ty = Quintic(y - fy);
  const uint64_t column0 = SplitMix64(key_round ^ static_cast<uint64_t>(ix));
  const uint64_t column1 = SplitMix64(key_round ^ static_cast<uint64_t>(ix + 1));
  auto lattice = [](uint64_t column, int64_t j) {
    return UnitFromHash(HashRest3(column ^ static_cast<uint64_t>(j)));
  };
  const double v00 = lattice(column0, iy), v10 = lattice(column1, iy);
  const double v01 = lattice(column0, iy + 1), v11 = lattice(column1, iy + 1);
  const double a = v00 + (v10 - v00) * tx;
  const double b = v01 + (v11 - v01) * tx;
  return a + (b - a) * ty;
}

// Fractal sum of value noise, normalised to [0, 1]. Each octave is rotated
// and shifted by a key-dependent amount so that lattices never line up.
template <typename Noise, typename Octave>
Noise MakeNoise(uint64_t key, double base_frequency, int octaves, double gain) {
  Noise noise;
  double amplitude = 1, frequency = base_frequency;
  for (int o = 0; o < octaves; ++o) {
    const uint64_t okey = Hash(key, 0x6f637476ULL, static_cast<uint64_t>(o));
    const double angle = 2 * M_PI * UnitFromHash(okey);
    Octave octave;
    octave.key_round = SplitMix64(okey);
    octave.cos = std::cos(angle);
    octave.sin = std::sin(angle);
    octave.shift_x = 100 * UnitFromHash(okey >> 7);
    octave.shift_y = 100 * UnitFromHash(okey >> 13);
    octave.frequency = frequency;
    octave.amplitude = amplitude;
    noise.octaves.push_back(octave);
    noise.norm += amplitude;
    amplitude *= gain;
    frequency *= 2.07;
  }
  return noise;
}

template <typename Noise>
double Fbm(const Noise& noise, const Eigen::Vector2d& uv) {
  double sum = 0;
  for (const auto& o : noise.octaves) {
    const double x = o.frequency * (o.cos * uv.x() - o.sin * uv.y()) + o.shift_x;
    const double y = o.frequency * (o.sin * uv.x() + o.cos * uv.y()) + o.shift_y;
    sum += o.amplitude * ValueNoise(o.key_round, x, y);
  }
  return sum / noise.norm;
}

Eigen::Vector3f HsvToRgb(double h, double s, double v) {
  h = 6 * (h - std::floor(h));
  const int i = static_cast<int>(h) % 6;
  const double f = h - std::floor(h);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  switch (i) {
    case 0: return Eigen::Vector3f(v, t, p);
    case 1: return Eigen::Vector3f(q, v, p);
    case 2: return Eigen::Vector3f(p, v, t);
    case 3: return Eigen::Vector3f(p, q, v);
    case 4: return Eigen::Vector3f(t, p, v);
    default: return Eigen::Vector3f(v, p, q);
  }
}

// Random flat shapes (disk, ring, rotated square, ellipse, stripe bar) in a
// jittered grid of cells of side `cell`; at most one shape per cell, reaching
// at most one cell beyond its own, so a 3x3 neighbourhood holds every shape
// that can cover a point. Returns the topmost shape's colour. The cells'
// hashes are Hash(key, i, j) (key_round = SplitMix64(key)), their values
// Hash(h, n).
bool ShapeColour(uint64_t key_round, const Eigen::Vector2d& uv, double cell,
                 double occupancy, Eigen::Vector3f* colour) {
  const int64_t ci = static_cast<int64_t>(std::floor(uv.x() / cell));
  const int64_t cj = static_cast<int64_t>(std::floor(uv.y() / cell));
  double best_priority = -1;
  for (int64_t dj = -1; dj <= 1; ++dj) {
    for (int64_t di = -1; di <= 1; ++di) {
      const int64_t i = ci + di, j = cj + dj;
      const uint64_t h = HashRest3(
          SplitMix64(key_round ^ static_cast<uint64_t>(i)) ^ static_cast<uint64_t>(j));
      const uint64_t h_round = SplitMix64(h);
      // Hash(h, n): its rounds of c, d and e are plain rounds.
      auto hash = [h_round](uint64_t n) { return SplitMix64(HashRest3(h_round ^ n)); };
      auto value = [&hash](uint64_t n) { return UnitFromHash(hash(n)); };
      if (value(1) >= occupancy) continue;  // empty cell
      const double priority = value(2);
      if (priority <= best_priority) continue;
      const Eigen::Vector2d centre((i + value(3)) * cell, (j + value(4)) * cell);
      const double radius = cell * (0.25 + 0.75 * value(5));
      const double angle = M_PI * value(6);
      const Eigen::Vector2d p = uv - centre;
      const double c = std::cos(angle), s = std::sin(angle);
      const double x = c * p.x() + s * p.y(), y = -s * p.x() + c * p.y();
      const int type = static_cast<int>(hash(7) % 5);
      bool inside = false;
      switch (type) {
        case 0: inside = x * x + y * y < radius * radius; break;
        case 1: {
          const double r2 = x * x + y * y;
          inside = r2 < radius * radius && r2 > 0.36 * radius * radius;
          break;
        }
        case 2: inside = std::abs(x) < 0.75 * radius && std::abs(y) < 0.75 * radius; break;
        case 3: inside = x * x / (radius * radius) + 4 * y * y / (radius * radius) < 1; break;
        default: inside = std::abs(x) < radius && std::abs(y) < 0.2 * radius; break;
      }
      if (!inside) continue;
      best_priority = priority;
      const double hue = value(8);
      const double saturation = 0.5 + 0.5 * value(9);
      // Dark or bright, rarely in between: strong edges against the noise.
      const double brightness = value(10) < 0.45 ? 0.08 + 0.15 * value(11)
                                                 : 0.8 + 0.2 * value(11);
      *colour = HsvToRgb(hue, saturation, brightness);
    }
  }
  return best_priority >= 0;
}

}  // namespace

std::string SceneOptions::Check() const {
  std::ostringstream error;
  if (!(checker_size_m > 0) || !std::isfinite(checker_size_m)) {
    error << "checker_size_m must be positive (got " << checker_size_m << ")";
  }
  return error.str();
}

double Face::Area() const { return (max_uv - min_uv).prod(); }

Eigen::Vector2d Face::UV(const Eigen::Vector3d& point) const {
  return Eigen::Vector2d(point[(axis + 1) % 3], point[(axis + 2) % 3]);
}

Eigen::Vector3d Face::PointFromUV(const Eigen::Vector2d& uv) const {
  Eigen::Vector3d point;
  point[axis] = offset;
  point[(axis + 1) % 3] = uv.x();
  point[(axis + 2) % 3] = uv.y();
  return point;
}

Scene::Scene(const SceneOptions& options) : options_(options) {
  const Eigen::Vector3d half(kRoomHalfX, kRoomHalfY, kRoomHalfZ);
  // The room's six faces, facing inwards.
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const Eigen::Vector2d min_uv(-half[u], -half[v]), max_uv(half[u], half[v]);
    AddFace(axis, -half[axis], +1, min_uv, max_uv);
    AddFace(axis, +half[axis], -1, min_uv, max_uv);
  }
  if (options_.with_boxes) {
    // Furniture, clear of the camera layouts (centres within |x|,|z| <= 1.2
    // at heights around y = 0). Recall +Y is down: the floor is y = 1.5.
    const std::vector<AlignedBox> boxes = {
        {{1.3, 0.6, 1.2}, {1.9, 1.5, 1.9}},       // cabinet in a corner, 0.9 m
        {{-1.8, 1.0, -0.4}, {-1.1, 1.5, 0.5}},    // low table-like block, 0.5 m
        {{-0.3, 0.9, -1.9}, {0.4, 1.5, -1.4}},    // chest against the back wall
        {{1.5, -1.5, -1.0}, {1.9, 1.5, -0.6}},    // floor-to-ceiling pillar
        {{-2.0, -0.5, 0.9}, {-1.7, -0.25, 1.8}},  // wall shelf, 2 m above floor
    };
    for (const AlignedBox& box : boxes) AddBox(box);
  }
  PrepareTextures();
  double total = 0;
  for (const Face& face : faces_) {
    total += face.Area();
    cumulative_area_.push_back(total);
  }
}

void Scene::AddFace(int axis, double offset, int sign, const Eigen::Vector2d& min_uv,
                    const Eigen::Vector2d& max_uv) {
  Face face;
  face.axis = axis;
  face.offset = offset;
  face.sign = sign;
  face.min_uv = min_uv;
  face.max_uv = max_uv;
  faces_.push_back(face);
}

void Scene::AddBox(const AlignedBox& box) {
  boxes_.push_back(box);
  const Eigen::Vector3d half(kRoomHalfX, kRoomHalfY, kRoomHalfZ);
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const Eigen::Vector2d min_uv(box.min[u], box.min[v]), max_uv(box.max[u], box.max[v]);
    // A face lying on a room face and pointing out of the room is never seen.
    if (box.min[axis] > -half[axis]) AddFace(axis, box.min[axis], -1, min_uv, max_uv);
    if (box.max[axis] < half[axis]) AddFace(axis, box.max[axis], +1, min_uv, max_uv);
  }
}

bool Scene::CastRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                    RayHit* hit) const {
  double best = std::numeric_limits<double>::infinity();
  int best_face = -1;
  for (size_t f = 0; f < faces_.size(); ++f) {
    const Face& face = faces_[f];
    const double d = direction[face.axis];
    if (face.sign * d >= 0) continue;  // parallel or seen from behind
    const double t = (face.offset - origin[face.axis]) / d;
    if (t <= kMinRange || t >= best) continue;
    const int u = (face.axis + 1) % 3, v = (face.axis + 2) % 3;
    const double pu = origin[u] + t * direction[u];
    const double pv = origin[v] + t * direction[v];
    if (pu < face.min_uv.x() - kEdgeEpsilon || pu > face.max_uv.x() + kEdgeEpsilon ||
        pv < face.min_uv.y() - kEdgeEpsilon || pv > face.max_uv.y() + kEdgeEpsilon) {
      continue;
    }
    best = t;
    best_face = static_cast<int>(f);
  }
  if (best_face < 0) return false;
  hit->range = best;
  hit->face_id = best_face;
  hit->point = origin + best * direction;
  hit->point[faces_[best_face].axis] = faces_[best_face].offset;  // exactly on the plane
  return true;
}

Eigen::Vector3f Scene::Colour(int face_id, const Eigen::Vector3d& point) const {
  const Eigen::Vector2d uv = faces_[face_id].UV(point);
  if (options_.texture == TextureKind::kChecker) {
    const double s = options_.checker_size_m;
    const int64_t parity = static_cast<int64_t>(std::floor(uv.x() / s)) +
                           static_cast<int64_t>(std::floor(uv.y() / s));
    const float value = (parity & 1) ? 0.92f : 0.08f;
    return Eigen::Vector3f::Constant(value);
  }
  return ProceduralColour(face_id, uv);
}

namespace {
// Shapes on three scales, the smallest drawn on top: (cell side in metres,
// probability that a cell holds a shape).
constexpr std::pair<double, double> kShapeLayers[] = {{0.06, 0.2}, {0.16, 0.35}, {0.45, 0.6}};
}  // namespace

void Scene::PrepareTextures() {
  textures_.clear();
  for (size_t face_id = 0; face_id < faces_.size(); ++face_id) {
    const uint64_t key = Hash(options_.seed, 0x726f6f6dULL, static_cast<uint64_t>(face_id));
    FaceTexture texture;
    // Luminance detail from 0.5 m down to ~8 mm.
    texture.detail = MakeNoise<Noise, NoiseOctave>(Hash(key, 1), 2.0, 7, 0.6);
    for (int k = 0; k < 3; ++k) {
      texture.shape_keys[k] = SplitMix64(
          Hash(key, 2, static_cast<uint64_t>(kShapeLayers[k].first * 1000)));
    }
    // Slowly varying tint per channel.
    for (int c = 0; c < 3; ++c) {
      texture.tint[c] =
          MakeNoise<Noise, NoiseOctave>(Hash(key, 3, static_cast<uint64_t>(c)), 0.8, 2, 0.5);
    }
    textures_.push_back(texture);
  }
}

Eigen::Vector3f Scene::ProceduralColour(int face_id, const Eigen::Vector2d& uv) const {
  const FaceTexture& texture = textures_[face_id];
  // Contrast-stretched detail.
  const double luminance = std::clamp(0.5 + 2.2 * (Fbm(texture.detail, uv) - 0.5), 0.0, 1.0);
  Eigen::Vector3f shape;
  for (int k = 0; k < 3; ++k) {
    if (ShapeColour(texture.shape_keys[k], uv, kShapeLayers[k].first, kShapeLayers[k].second,
                    &shape)) {
      return (shape * static_cast<float>(0.75 + 0.5 * luminance)).cwiseMin(1.0f);
    }
  }
  Eigen::Vector3f colour;
  for (int c = 0; c < 3; ++c) {
    const double tint = Fbm(texture.tint[c], uv);
    colour[c] = static_cast<float>(luminance * (0.35 + 1.3 * tint));
  }
  return colour.cwiseMax(0.0f).cwiseMin(1.0f);
}

bool Scene::IsFreeSpace(const Eigen::Vector3d& point) const {
  const Eigen::Vector3d half(kRoomHalfX, kRoomHalfY, kRoomHalfZ);
  if ((point.array().abs() >= half.array()).any()) return false;
  for (const AlignedBox& box : boxes_) {
    if ((point.array() >= box.min.array()).all() && (point.array() <= box.max.array()).all()) {
      return false;
    }
  }
  return true;
}

RayHit Scene::SampleSurfacePoint(std::mt19937_64* rng) const {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double a = unit(*rng) * cumulative_area_.back();
  const int f = static_cast<int>(
      std::min<size_t>(std::upper_bound(cumulative_area_.begin(), cumulative_area_.end(), a) -
                           cumulative_area_.begin(),
                       faces_.size() - 1));
  const Face& face = faces_[f];
  const Eigen::Vector2d uv(face.min_uv.x() + unit(*rng) * (face.max_uv.x() - face.min_uv.x()),
                           face.min_uv.y() + unit(*rng) * (face.max_uv.y() - face.min_uv.y()));
  RayHit hit;
  hit.face_id = f;
  hit.point = face.PointFromUV(uv);
  return hit;
}

}  // namespace synthetic
}  // namespace sphera
