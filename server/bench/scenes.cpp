#include "server/bench/scenes.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

namespace fishtank {

namespace {
constexpr float kLatticeSpacing = kMaxBallDiameter + 0.05f;
constexpr float kTankHeight = 40.0f;

int wide_lattice_side(std::uint32_t balls) {
  const int layers = static_cast<int>(kTankHeight / kLatticeSpacing);
  return std::max(2, static_cast<int>(std::ceil(std::sqrt(double(balls) / layers))));
}
}  // namespace

bool is_known_scene(const std::string& name) { return name == "tank" || name == "wide"; }

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
  if (spec.name == "tank") {
    AddResult added = world.add_balls(spec.balls);
    return added.refusal;
  }
  // wide: a loose lattice, layer by layer from the floor, kinds taking turns.
  const int side = wide_lattice_side(spec.balls);
  const TankBounds& t = world.params().tank;
  std::mt19937_64 rng(spec.seed);
  auto jitter = [&rng] { return static_cast<float>(rng() >> 40) * (1.0f / 16777216.0f) - 0.5f; };
  for (std::uint32_t b = 0; b < spec.balls; ++b) {
    std::uint32_t layer = b / (side * side), cell = b % (side * side);
    Vec3 p{t.min.x + (cell % side + 0.5f) * kLatticeSpacing, t.min.y + (layer + 0.5f) * kLatticeSpacing,
           t.min.z + (cell / side + 0.5f) * kLatticeSpacing};
    world.place_ball(static_cast<int>(b % kKindCount), p, Vec3{jitter(), jitter(), jitter()});
  }
  return "";
}

SettleReport settle(World& world, const SceneSpec& spec) {
  const double limit = spec.max_settle_seconds > 0.0 ? spec.max_settle_seconds : (spec.name == "wide" ? 4.0 : 90.0);
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t first_step = world.steps();
  // Checked every tenth of a simulated second, reported every tenth check.
  constexpr std::uint64_t kChecksPerReport = 10;
  const auto check_every = static_cast<std::uint64_t>(std::max(1.0, 0.1 / world.dt()));
  SettleReport report;
  for (;;) {
    world.step();
    const std::uint64_t done = world.steps() - first_step;
    if (done % check_every != 0) continue;
    const double sim = done * double(world.dt());
    const double energy = world.ball_count() ? world.kinetic_energy() / world.ball_count() : 0.0;
    if (done / check_every % kChecksPerReport == 0)
      std::fprintf(stderr, "settling: %.0f s simulated, %u balls in, %u queued, kinetic energy %.4f J/ball\n", sim,
                   world.ball_count(), world.pending(), energy);
    report.settled = world.pending() == 0 && energy < kRestEnergy;
    if (report.settled || sim >= limit) {
      report.sim_seconds = sim;
      report.steps = done;
      break;
    }
  }
  report.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace fishtank
