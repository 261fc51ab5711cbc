#include "server/scenes/scene_presets.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "common/scene_names.h"

namespace fishtank {

namespace {
constexpr float kGap = 0.05f;  // between neighbours of a placed lattice, so none starts in contact
constexpr float kLatticeSpacing = kMaxBallDiameter + kGap;
constexpr float kTankHeight = 40.0f;
constexpr float kSmallSpacing = kMinBallDiameter + kGap;
constexpr float kDamWidth = 6.0f;         // the column's extent along x, against the -x wall
constexpr float kDropHeight = 12.0f;      // the large balls' lattice starts this far below the ceiling
constexpr std::uint32_t kDropShare = 10;  // one ball in this many of the drop scene is large

int wide_lattice_side(std::uint32_t balls) {
  const int layers = static_cast<int>(kTankHeight / kLatticeSpacing);
  return std::max(2, static_cast<int>(std::ceil(std::sqrt(double(balls) / layers))));
}

// Cells of `spacing` that fit along `length` (a length that is a whole number
// of cells gives that number, whatever the float rounding).
int cells_along(float length, float spacing) { return std::max(1, static_cast<int>(length / spacing + 1e-3f)); }

// Balls a lattice of `spacing` holds in the box from `lo` to `hi`.
std::uint32_t lattice_fit(Vec3 lo, Vec3 hi, float spacing) {
  return static_cast<std::uint32_t>(cells_along(hi.x - lo.x, spacing)) *
         static_cast<std::uint32_t>(cells_along(hi.z - lo.z, spacing)) *
         static_cast<std::uint32_t>(cells_along(hi.y - lo.y, spacing));
}

// Places `count` balls (at most lattice_fit) on a lattice filling the box from `lo` to `hi`, x fastest, then z,
// then up; kind_of(b) gives ball b's kind. Each gets a small random velocity so the lattice does not stay one.
template <class KindOf>
void place_lattice(World& world, Vec3 lo, Vec3 hi, float spacing, std::uint32_t count, std::mt19937_64& rng,
                   KindOf kind_of) {
  const int nx = cells_along(hi.x - lo.x, spacing), nz = cells_along(hi.z - lo.z, spacing);
  const std::uint32_t per_layer = static_cast<std::uint32_t>(nx * nz);
  auto jitter = [&rng] { return static_cast<float>(rng() >> 40) * (1.0f / 16777216.0f) - 0.5f; };
  for (std::uint32_t b = 0; b < count; ++b) {
    const std::uint32_t layer = b / per_layer, cell = b % per_layer;
    const Vec3 p{lo.x + (cell % nx + 0.5f) * spacing, lo.y + (layer + 0.5f) * spacing,
                 lo.z + (cell / nx + 0.5f) * spacing};
    const float vx = jitter(), vy = jitter(), vz = jitter();  // in this order, whatever the compiler's
    world.place_ball(kind_of(b), p, Vec3{vx, vy, vz});
  }
}

// The boxes each placed scene fills: the dam's column against the -x wall; the drop's bed of small balls below
// the large ones' lattice, which starts kDropHeight under the ceiling.
Vec3 dam_top(const TankBounds& t) { return {t.min.x + kDamWidth, t.max.y, t.max.z}; }
Vec3 bed_top(const TankBounds& t) { return {t.max.x, t.max.y - kDropHeight, t.max.z}; }
Vec3 drop_bottom(const TankBounds& t) { return {t.min.x, t.max.y - kDropHeight, t.min.z}; }
std::uint32_t drop_large(std::uint32_t balls) { return balls / kDropShare; }

}  // namespace

std::uint32_t default_balls(const std::string& name) {
  // In kSceneNames' order: the product's start, the benchmark's count, and
  // enough for the column and the bed to show at real time on two cores.
  constexpr std::array<std::uint32_t, kSceneNames.size()> kDefaultBalls{1000, 6000, 3000, 3000};
  for (std::size_t i = 0; i < kSceneNames.size(); ++i)
    if (name == kSceneNames[i]) return kDefaultBalls[i];
  return 0;
}

TankBounds scene_tank(const SceneSpec& spec) {
  TankBounds tank;
  if (spec.name == "wide") {
    float half = 0.5f * wide_lattice_side(spec.balls) * kLatticeSpacing;
    tank.min = {-half, 0.0f, -half};
    tank.max = {half, kTankHeight, half};
  }
  return tank;
}

std::uint32_t scene_capacity(const World& world, const std::string& name) {
  const TankBounds& t = world.params().tank;
  if (name == "tank") return world.max_balls();
  if (name == "dam-break") return lattice_fit(t.min, dam_top(t), kSmallSpacing);
  if (name == "drop") {
    // The most balls whose large tenth fits the lattice under the ceiling and whose rest fits the bed below it.
    const std::uint32_t large = lattice_fit(drop_bottom(t), t.max, kLatticeSpacing);
    const std::uint32_t bed = lattice_fit(t.min, bed_top(t), kSmallSpacing);
    std::uint32_t balls = large * kDropShare + (kDropShare - 1);
    while (balls > 0 && (drop_large(balls) > large || balls - drop_large(balls) > bed)) --balls;
    return balls;
  }
  return lattice_fit(t.min, t.max, kLatticeSpacing);  // wide: its tank is sized for the count asked for
}

std::string populate(World& world, const SceneSpec& spec) {
  if (spec.name == "tank") return spec.balls > 0 ? world.add_balls(spec.balls).refusal : "";
  const std::uint32_t capacity = scene_capacity(world, spec.name), balls = std::min(spec.balls, capacity);
  const TankBounds& t = world.params().tank;
  std::mt19937_64 rng(spec.seed);
  if (spec.name == "wide") {
    auto turns = [](std::uint32_t b) { return static_cast<int>(b % kKindCount); };
    place_lattice(world, t.min, t.max, kLatticeSpacing, balls, rng, turns);
  } else if (spec.name == "dam-break") {
    place_lattice(world, t.min, dam_top(t), kSmallSpacing, balls, rng, [](std::uint32_t) { return 0; });
  } else {
    const std::uint32_t large = drop_large(balls);
    place_lattice(world, t.min, bed_top(t), kSmallSpacing, balls - large, rng, [](std::uint32_t) { return 0; });
    place_lattice(world, drop_bottom(t), t.max, kLatticeSpacing, large, rng,
                  [](std::uint32_t) { return kKindCount - 1; });
  }
  if (balls == spec.balls) return "";
  return "the " + spec.name + " scene holds at most " + std::to_string(capacity) + " balls; " +
         std::to_string(spec.balls) + " were asked for, " + std::to_string(balls) + " placed";
}

}  // namespace fishtank
