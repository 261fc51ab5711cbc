#include "server/accuracy/stability.h"

#include <algorithm>
#include <cmath>

#include "server/accuracy/scenes.h"
#include "server/physics/world.h"
#include "server/physics/world_measures.h"

namespace fishtank::accuracy {
namespace {

constexpr double kRestitution = 0.6;

// Balls that are not finite or have left the tank: a soft contact lets a
// ball's centre sink past a wall (a large overlap, judged as inaccuracy), so
// only a centre more than a largest diameter outside counts as lost.
std::uint32_t lost_balls(const World& world) {
  const TankBounds& t = world.params().tank;
  const float margin = kMaxBallDiameter;
  std::uint32_t lost = 0;
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) {
    const Float4& p = world.positions()[i];
    const Float4& v = world.velocities()[i];
    const bool inside = p.x >= t.min.x - margin && p.x <= t.max.x + margin && p.y >= t.min.y - margin &&
                        p.y <= t.max.y + margin && p.z >= t.min.z - margin && p.z <= t.max.z + margin;
    if (!inside || !std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) ++lost;  // NaN is not inside
  }
  return lost;
}

struct PileResult {
  bool finite_and_contained;
  double overlap, energy_ratio;
};

PileResult run_pile(double k, double dt, const Kernels& kernels) {
  PhysicsParams p;
  p.stiffness = static_cast<float>(k);
  p.restitution = static_cast<float>(kRestitution);
  p.dt = static_cast<float>(dt);
  p.tank.min = {-2.0f, 0.0f, -2.0f};
  p.tank.max = {2.0f, 10.0f, 2.0f};
  World world(p, kernels, 1, 1);
  // A loose lattice, nudged off its columns so the pile does not stack in towers.
  int i = 0;
  for (int y = 0; y < 4; ++y)
    for (int x = -1; x <= 1; ++x)
      for (int z = -1; z <= 1; ++z, ++i)
        world.place_ball(
            0, {1.25f * x + 0.1f * std::sin(1.7f * i), 0.6f + 1.25f * y, 1.25f * z + 0.1f * std::cos(2.3f * i)},
            {0.0f, 0.0f, 0.0f});

  const double start = kinetic_energy(world) + potential_energy(world);
  double ratio = 1.0;
  const long steps = std::lround(std::ceil(kPileSeconds / dt));
  for (long s = 1; s <= steps; ++s) {
    world.step();
    if (s % 16 != 0 && s != steps) continue;
    if (lost_balls(world) > 0) return {false, NAN, NAN};
    ratio = std::max(ratio, (kinetic_energy(world) + potential_energy(world)) / start);
    if (ratio > kBlowUp) break;
  }
  return {true, max_overlap_fraction(world), ratio};
}

}  // namespace

const char* stability_name(Stability s) {
  switch (s) {
    case Stability::kUnstable:
      return "unstable";
    case Stability::kInaccurate:
      return "inaccurate";
    case Stability::kAccurate:
      return "accurate";
  }
  return "?";
}

StabilityCell classify(double k, double dt, const Kernels& kernels) {
  SceneConfig config;
  config.k = k;
  config.restitution = kRestitution;
  config.kernels = &kernels;
  const double e = measured_restitution(methods().front(), config, dt, 0, 0);
  const PileResult pile = run_pile(k, dt, kernels);

  StabilityCell cell{k, dt, e, pile.overlap, pile.energy_ratio, Stability::kAccurate};
  if (!pile.finite_and_contained || pile.energy_ratio > kBlowUp || !(e <= 1.0))
    cell.stability = Stability::kUnstable;
  else if (std::fabs(e - kRestitution) > kRestitutionTolerance * kRestitution || pile.overlap > kOverlapTolerance)
    cell.stability = Stability::kInaccurate;
  return cell;
}

}  // namespace fishtank::accuracy
