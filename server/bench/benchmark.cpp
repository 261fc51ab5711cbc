#include "server/bench/benchmark.h"

#include <sys/resource.h>

#include <chrono>

namespace fishtank {

namespace {
double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux reports KiB
}
}  // namespace

nlohmann::json time_steps(World& world, const BenchSpec& spec, const SettleReport& settle) {
  const PhaseSeconds before = world.phase_seconds();
  const std::uint64_t rebuilds_before = world.rebuilds();
  const auto start = std::chrono::steady_clock::now();
  for (std::uint64_t s = 0; s < spec.steps; ++s) world.step();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const PhaseSeconds& after = world.phase_seconds();
  const TankBounds& tank = world.params().tank;

  nlohmann::json j;
  j["scene"] = spec.scene.name;
  j["variant"] = world.kernels().variant;
  j["simd"] = world.kernels().simd;
  j["threads"] = world.threads();
  j["balls"] = world.ball_count();
  j["steps"] = spec.steps;
  j["seconds"] = seconds;
  j["steps_per_s"] = spec.steps / seconds;
  j["ball_steps_per_s"] = double(spec.steps) * world.ball_count() / seconds;
  j["ns_per_ball_step"] = seconds * 1e9 / (double(spec.steps) * std::max(1u, world.ball_count()));
  j["dt"] = world.dt();
  j["k"] = world.params().stiffness;
  j["restitution"] = world.params().restitution;
  j["max_overlap"] = world.max_overlap_fraction();
  j["pile_top"] = world.pile_top();
  j["tank"] = {{"min", {tank.min.x, tank.min.y, tank.min.z}}, {"max", {tank.max.x, tank.max.y, tank.max.z}}};
  j["mean_neighbours"] = world.mean_neighbours();
  j["rebuilds"] = world.rebuilds() - rebuilds_before;
  j["kinetic_energy_per_ball"] = world.ball_count() ? world.kinetic_energy() / world.ball_count() : 0.0;
  j["settle"] = {{"settled", settle.settled},
                 {"sim_seconds", settle.sim_seconds},
                 {"wall_seconds", settle.wall_seconds},
                 {"steps", settle.steps}};
  j["phase_seconds"] = {{"kick_drift", after.kick_drift - before.kick_drift},
                        {"neighbours", after.neighbours - before.neighbours},
                        {"forces", after.forces - before.forces},
                        {"spawn", after.spawn - before.spawn}};
  j["peak_rss_mib"] = peak_rss_mib();
  j["seed"] = spec.scene.seed;
  return j;
}

}  // namespace fishtank
