#include "server/realtime_loop.h"

#include <chrono>
#include <thread>

namespace fishtank {

namespace {
using Clock = std::chrono::steady_clock;
// A hiccup shorter than this is caught up on (in batches that each keep to
// the budget); past it the loop lets simulated time slip: slow motion.
constexpr double kMaxLagSeconds = 0.05;
// How long before a batch the workers are woken: enough for a sleeping thread
// to be scheduled, well inside the pool's 1 ms of polling.
constexpr double kWakeLeadSeconds = 0.0003;

double seconds_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}
}  // namespace

TunedStepper::TunedStepper(World& world, bool tune) : world_(world), epoch_(Clock::now()) {
  if (!tune) return;
  tuner_.emplace(world.threads());
  world.set_thread_limit(tuner_->threads());
}

void TunedStepper::step() {
  one_thread_steps_ += world_.thread_limit() == 1;
  if (!tuner_) {
    world_.step();
    return;
  }
  // The tuner times the step pass alone: a step that rebuilds the lists costs a score of passes, and
  // would make whichever count it fell on look dearer until the estimate forgot it.
  const double pass_before = world_.phase_seconds().step_pass;
  world_.step();
  const double pass = world_.phase_seconds().step_pass - pass_before;
  const double now = seconds_between(epoch_, Clock::now());
  machine_load_.update(now);  // after the step's clock: a reading is not a step's cost
  using Load = ThreadTuner::Load;
  const Load load = !machine_load_.room_for(world_.threads()) ? Load::kOneThread
                    : machine_load_.shared_per_thread()       ? Load::kEveryThread
                                                              : Load::kMeasure;
  world_.set_thread_limit(tuner_->record(pass, 1, now, load));
}

void run_realtime(TunedStepper& stepper, const LoopOptions& options, const std::atomic<bool>& stop) {
  World& world = stepper.world();
  const double dt = world.dt();
  RunControl real_time;
  RunControl& control = options.control ? *options.control : real_time;
  const Clock::time_point start = Clock::now();
  double sim_clock = 0.0;  // the wall time by which the steps done so far were due
  LoopStatus status;
  Clock::time_point window_start = start;
  std::uint64_t window_steps = 0;
  double window_busy = 0.0;

  while (!stop.load(std::memory_order_relaxed)) {
    const double now = seconds_between(start, Clock::now());
    if (options.duration > 0.0 && now >= options.duration) break;
    const Clock::time_point busy_start = Clock::now();
    if (options.at_step_boundary) options.at_step_boundary(world, status);
    // A step is due every dt / time_scale of wall time; a paused world owes none.
    const double wall_per_step = dt / control.time_scale;
    if (control.paused) {
      sim_clock = now;
    } else if (now - sim_clock > kMaxLagSeconds) {
      status.dropped_steps += static_cast<std::uint64_t>((now - sim_clock - kMaxLagSeconds) / wall_per_step);
      sim_clock = now - kMaxLagSeconds;
    }
    // Steps are due up to `now`, but the batch stops at its budget so that
    // snapshots, status and commands keep their rate whatever a step costs.
    const Clock::time_point budget_end =
        busy_start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.batch_seconds));
    auto within_budget = [&](std::uint64_t done) { return done == 0 || Clock::now() < budget_end; };
    std::uint64_t batch_steps = 0;
    if (control.paused) {
      for (; control.steps_to_run > 0 && within_budget(batch_steps); --control.steps_to_run, ++batch_steps)
        stepper.step();
    } else {
      for (; sim_clock + wall_per_step <= now && within_budget(batch_steps); sim_clock += wall_per_step, ++batch_steps)
        stepper.step();
    }
    const Clock::time_point busy_end = Clock::now();
    const double busy = seconds_between(busy_start, busy_end);
    window_busy += busy;
    window_steps += batch_steps;
    status.threads = stepper.threads();
    status.crowding_cores = stepper.crowding_cores();

    const double window = seconds_between(window_start, busy_end);
    if (window >= options.status_interval) {
      status.steps_per_s = window_steps / window;
      status.load = window_busy / window;
      status.time_scale = window_steps * dt / window;
      if (options.on_status) options.on_status(world, status);
      window_start = busy_end;
      window_steps = 0;
      status.dropped_steps = 0;
      window_busy = 0.0;
    }
    if (control.paused && control.steps_to_run > 0) continue;  // asked-for steps run back to back
    // Sleep until a batch of steps is due rather than a single one, and wake
    // the worker threads a little before it: waking a sleeping thread costs
    // more than the batch would otherwise wait for.
    const double next_batch = sim_clock + std::max(wall_per_step, options.batch_seconds);
    const double wait = next_batch - seconds_between(start, Clock::now());
    if (wait > kWakeLeadSeconds) std::this_thread::sleep_for(std::chrono::duration<double>(wait - kWakeLeadSeconds));
    world.wake_workers();
    if (wait > 0.0)
      std::this_thread::sleep_until(
          start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(next_batch)));
  }
}

}  // namespace fishtank
