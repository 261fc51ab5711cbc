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

// Places up to `count` balls on a lattice filling the box from `lo` to `hi`,
// x fastest, then z, then up; kind_of(b) gives ball b's kind. Each gets a
// small random velocity so the lattice does not stay one. Returns how many fitted.
template <class KindOf>
std::uint32_t place_lattice(World& world, Vec3 lo, Vec3 hi, float spacing, std::uint32_t count, std::mt19937_64& rng,
                            KindOf kind_of) {
  const int nx = cells_along(hi.x - lo.x, spacing), nz = cells_along(hi.z - lo.z, spacing);
  const std::uint32_t per_layer = static_cast<std::uint32_t>(nx * nz);
  const std::uint32_t fit = per_layer * static_cast<std::uint32_t>(cells_along(hi.y - lo.y, spacing));
  auto jitter = [&rng] { return static_cast<float>(rng() >> 40) * (1.0f / 16777216.0f) - 0.5f; };
  const std::uint32_t placed = std::min(count, fit);
  for (std::uint32_t b = 0; b < placed; ++b) {
    const std::uint32_t layer = b / per_layer, cell = b % per_layer;
    const Vec3 p{lo.x + (cell % nx + 0.5f) * spacing, lo.y + (layer + 0.5f) * spacing,
                 lo.z + (cell / nx + 0.5f) * spacing};
    const float vx = jitter(), vy = jitter(), vz = jitter();  // in this order, whatever the compiler's
    world.place_ball(kind_of(b), p, Vec3{vx, vy, vz});
  }
  return placed;
}

std::string too_many(const SceneSpec& spec, std::uint32_t placed) {
  if (placed == spec.balls) return "";
  return "the " + spec.name + " scene holds " + std::to_string(placed) + " balls; " + std::to_string(spec.balls) +
         " were asked for";
}
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

std::string populate(World& world, const SceneSpec& spec) {
  if (spec.name == "tank") return spec.balls > 0 ? world.add_balls(spec.balls).refusal : "";
  const TankBounds& t = world.params().tank;
  std::mt19937_64 rng(spec.seed);
  if (spec.name == "wide") {
    auto turns = [](std::uint32_t b) { return static_cast<int>(b % kKindCount); };
    return too_many(spec, place_lattice(world, t.min, t.max, kLatticeSpacing, spec.balls, rng, turns));
  }
  if (spec.name == "dam-break") {
    const Vec3 hi{t.min.x + kDamWidth, t.max.y, t.max.z};
    return too_many(spec,
                    place_lattice(world, t.min, hi, kSmallSpacing, spec.balls, rng, [](std::uint32_t) { return 0; }));
  }
  // drop: the bed first, from the floor; then the large balls, under the ceiling.
  const std::uint32_t large = spec.balls / kDropShare;
  std::uint32_t placed =
      place_lattice(world, t.min, t.max, kSmallSpacing, spec.balls - large, rng, [](std::uint32_t) { return 0; });
  const Vec3 lo{t.min.x, t.max.y - kDropHeight, t.min.z};
  placed += place_lattice(world, lo, t.max, kLatticeSpacing, large, rng, [](std::uint32_t) { return kKindCount - 1; });
  return too_many(spec, placed);
}

}  // namespace fishtank
