#include "server/bench/benchmark.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "common/number_text.h"
#include "server/bench/line_transfer.h"
#include "server/physics/world_measures.h"

namespace fishtank {

namespace {
double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux reports KiB
}
}  // namespace

nlohmann::json time_steps(TunedStepper& stepper, const BenchSpec& spec, const SettleReport& settle) {
  World& world = stepper.world();
  // The cores' placement before and after: it moves the figures of scenes
  // whose threads share lines (line_transfer.h).
  const std::optional<LineTransfer> transfer_before = time_line_transfer(world.cpus());
  const PhaseSeconds before = world.phase_seconds();
  const std::uint64_t rebuilds_before = world.rebuilds(), kept_before = world.lists_kept_by_checks();
  world.reset_thread_shares();
  const std::uint64_t one_thread_before = stepper.steps_on_one_thread();
  // A shared machine's noise comes in bursts: timing several windows and
  // reporting the median keeps one burst from deciding the figure.
  const std::uint32_t windows = static_cast<std::uint32_t>(std::clamp<std::uint64_t>(spec.windows, 1, spec.steps));
  std::vector<double> window_seconds;
  std::uint64_t done = 0;
  for (std::uint32_t w = 0; w < windows; ++w) {
    const std::uint64_t until = spec.steps * (w + 1) / windows;
    const auto start = std::chrono::steady_clock::now();
    for (; done < until; ++done) stepper.step();
    window_seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  double seconds = 0.0;
  std::vector<double> rates;
  for (std::uint32_t w = 0; w < windows; ++w) {
    seconds += window_seconds[w];
    const double window_steps = double(spec.steps * (w + 1) / windows - spec.steps * w / windows);
    rates.push_back(window_steps * world.ball_count() / window_seconds[w]);
  }
  std::vector<double> sorted = rates;
  std::sort(sorted.begin(), sorted.end());
  const double median_rate =
      sorted.size() % 2 ? sorted[sorted.size() / 2] : 0.5 * (sorted[sorted.size() / 2 - 1] + sorted[sorted.size() / 2]);
  const PhaseSeconds& after = world.phase_seconds();
  const std::optional<LineTransfer> transfer_after = time_line_transfer(world.cpus());
  const TankBounds& tank = world.params().tank;

  nlohmann::json j;
  j["scene"] = spec.scene.name;
  j["variant"] = world.kernels().variant;
  j["simd"] = world.kernels().simd;
  j["threads"] = world.threads();
  j["thread_shares"] = world.thread_shares();  // of the items the timed steps' passes computed
  // The fraction of the timed steps taken on one thread: the tuner's choice, or too few balls to split.
  j["one_thread_step_fraction"] =
      double(stepper.steps_on_one_thread() - one_thread_before) / std::max<std::uint64_t>(1, spec.steps);
  // Cores work in other sessions kept busy at the end (MachineLoad), which keeps the steps on one thread;
  // null untuned (--fixed-threads, or one thread).
  if (const double crowding = stepper.crowding_cores(); crowding >= 0.0)
    j["crowding_cores"] = crowding;
  else
    j["crowding_cores"] = nullptr;
  j["balls"] = world.ball_count();
  j["steps"] = spec.steps;
  j["seconds"] = seconds;
  j["ball_steps_per_s"] = median_rate;  // median over the windows
  j["steps_per_s"] = median_rate / std::max(1u, world.ball_count());
  j["ns_per_ball_step"] = 1e9 / median_rate;
  j["window_ball_steps_per_s"] = rates;
  j["dt"] = world.params().dt > 0.0f ? shortest_decimal(world.dt()) : world.dt();  // as typed where given
  // Balls this build holds in real time at this dt: ball-steps per second times simulated seconds per step.
  j["realtime_capacity_balls"] = median_rate * world.dt();
  const PhysicsParams& params = world.params();
  // The per-collision restitution error the dt was chosen for; none where --dt or --steps-per-contact chose it.
  j["tolerance"] = dt_from_tolerance(params) ? nlohmann::json(shortest_decimal(params.tolerance)) : nullptr;
  j["steps_per_contact"] = params.dt > 0.0f ? nlohmann::json(contact_duration(params.stiffness) / world.dt())
                                            : nlohmann::json(steps_per_contact(params));
  j["dt_from_tolerance"] = dt_from_tolerance(params);
  j["k"] = shortest_decimal(params.stiffness);
  j["restitution"] = shortest_decimal(params.restitution);
  j["max_overlap"] = max_overlap_fraction(world);
  j["overlap_warning"] = overlap_warning(world);  // empty while the largest overlap is within kOverlapWarning
  j["pile_top"] = pile_top(world);
  j["tank"] = {{"min", {tank.min.x, tank.min.y, tank.min.z}}, {"max", {tank.max.x, tank.max.y, tank.max.z}}};
  j["mean_neighbours"] = mean_neighbours(world);
  j["rebuilds"] = world.rebuilds() - rebuilds_before;
  j["prefetch_ahead"] = world.beyond_cache();  // --prefetch-from
  j["skin"] = world.skin();                    // at the end (PhysicsParams::skin 0: it follows the motion)
  // Steps that kept the lists after checking the balls that moved past skin/2.
  j["lists_kept_after_check"] = world.lists_kept_by_checks() - kept_before;
  j["kinetic_energy_per_ball"] = world.ball_count() ? kinetic_energy(world) / world.ball_count() : 0.0;
  j["max_speed"] = max_speed(world);  // the fastest ball, m/s
  j["settle"] = {{"settled", settle.settled},
                 {"sim_seconds", settle.sim_seconds},
                 {"wall_seconds", settle.wall_seconds},
                 {"steps", settle.steps}};
  j["phase_seconds"] = {
      {"neighbours", after.neighbours - before.neighbours}, {"sort", after.sort - before.sort},
      {"list_build", after.list_build - before.list_build}, {"far_checks", after.stray_checks - before.stray_checks},
      {"step_pass", after.step_pass - before.step_pass},    {"spawn", after.spawn - before.spawn}};
  if (transfer_before && transfer_after)
    j["line_transfer_ns"] = {{"cpus", {transfer_before->cpu_a, transfer_before->cpu_b}},
                             {"before", transfer_before->ns},
                             {"after", transfer_after->ns}};
  else
    j["line_transfer_ns"] = nullptr;  // fewer than two CPUs
  j["peak_rss_mib"] = peak_rss_mib();
  j["seed"] = spec.scene.seed;
  return j;
}

}  // namespace fishtank
