#include "server/bench/scenes.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "server/physics/world_measures.h"

namespace fishtank {

SettleReport settle(TunedStepper& stepper, const SceneSpec& spec) {
  const World& world = stepper.world();
  const double limit = spec.max_settle_seconds > 0.0 ? spec.max_settle_seconds : (spec.name == "wide" ? 4.0 : 300.0);
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t first_step = world.steps();
  // Checked every tenth of a simulated second, reported every tenth check.
  constexpr std::uint64_t kChecksPerReport = 10;
  const auto check_every = static_cast<std::uint64_t>(std::max(1.0, 0.1 / world.dt()));
  SettleReport report;
  RestWatch rest;
  for (;;) {
    stepper.step();
    const std::uint64_t done = world.steps() - first_step;
    if (done % check_every != 0) continue;
    const double sim = done * double(world.dt());
    const double energy = world.ball_count() ? kinetic_energy(world) / world.ball_count() : 0.0;
    if (done / check_every % kChecksPerReport == 0)
      std::fprintf(stderr, "settling: %.1f s simulated, %u balls in, %u queued, kinetic energy %.2g J/ball\n", sim,
                   world.ball_count(), world.pending(), energy);
    report.settled = rest.settled(world.pending() == 0 && energy < kRestEnergy);
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
