#include "server/realtime_loop.h"

#include <algorithm>
#include <chrono>
#include <thread>

namespace fishtank {

namespace {
using Clock = std::chrono::steady_clock;
// A hiccup shorter than this is caught up on (in batches that each keep to
// the budget); past it the loop lets simulated time slip: slow motion.
constexpr double kMaxLagSeconds = 0.05;
// How long before a batch the workers are woken: enough for a sleeping thread
// to be scheduled, well inside the time the pool's workers poll before they
// sleep (worker_pool.cpp's kWorkerSpin).
constexpr double kWakeLeadSeconds = 0.0003;

// The rates snapshots carry are measured over at most this long, whatever the
// status line's interval: a viewer's figures must not wait for a long one.
constexpr double kLiveWindowSeconds = 1.0;
// After people pause, resume or set another time scale, the live window starts again and
// ends after this: the viewers' figures then tell the new pace within it, not a second on.
constexpr double kWindowAfterChangeSeconds = 0.2;

double seconds_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

// Steps and busy time since `start`, turned into a status's rates once `length` has passed.
// Its times are when steps fell due (the loop's sim_clock), not when they ran: a window
// ended between steps far apart, or at a step woken late, would count a step short and
// read as slow motion. Only time dropped while behind lowers the time scale. The busy
// share is of the wall clock's time (wall_start), which a machine behind runs ahead of.
// The simulated seconds people asked for are summed too (none while paused), so that a
// window in which they paused, resumed or set another time scale is not read as slow motion.
struct RateWindow {
  double start;
  double wall_start;
  double length;
  double first_length = 0.0;  // above 0: this window ends after that instead (restart)
  std::uint64_t steps = 0;
  double busy = 0.0;
  double running = 0.0;  // of the window's time, that not paused
  double asked = 0.0;    // simulated seconds the time scale set asked for

  void add(std::uint64_t batch_steps, double batch_busy, double running_seconds, double asked_seconds) {
    steps += batch_steps;
    busy += batch_busy;
    running += running_seconds;
    asked += asked_seconds;
  }
  // Whether it has ended at `end` (wall_end on the wall clock); then its rates are written into status
  // and it starts again.
  bool close(double end, double wall_end, double dt, LoopStatus& status) {
    const double span = end - start;
    if (span < (first_length > 0.0 ? first_length : length)) return false;
    status.steps_per_s = steps / span;
    status.load = busy / (wall_end - wall_start);  // its batches all lie within the window
    status.time_scale = steps * dt / (running > 0.0 ? running : span);
    status.pace_kept = asked > 0.0 ? steps * dt / asked : 1.0;
    *this = {end, wall_end, length};
    return true;
  }
  void restart(double at, double wall_at, double ends_after) {
    *this = {at, wall_at, length, std::min(ends_after, length)};
  }
};
}  // namespace

TunedStepper::TunedStepper(World& world, bool tune) : world_(world), epoch_(Clock::now()) {
  if (!tune || world.threads() == 1) return;  // one thread has nothing to choose, nor other sessions to blame
  tuner_.emplace(world.threads());
  world.set_thread_limit(tuner_->threads());
}

void TunedStepper::step() {
  one_thread_steps_ += world_.stepping_threads() == 1;
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
  LoopStatus status;       // what at_step_boundary sees: rates of the latest live window
  RateWindow live{0.0, 0.0, std::min(options.status_interval, kLiveWindowSeconds)};
  RateWindow line{0.0, 0.0, options.status_interval};
  bool paused_was = control.paused;
  double scale_was = control.time_scale;

  while (!stop.load(std::memory_order_relaxed)) {
    const double now = seconds_between(start, Clock::now());
    if (options.duration > 0.0 && now >= options.duration) break;
    const Clock::time_point busy_start = Clock::now();
    const double clock_before = sim_clock;
    if (options.at_step_boundary) options.at_step_boundary(world, status);
    if (control.paused != paused_was || control.time_scale != scale_was) {
      live.restart(clock_before, now, kWindowAfterChangeSeconds);
      paused_was = control.paused;
      scale_was = control.time_scale;
    }
    // A step is due every dt / time_scale of wall time; a paused world owes none.
    const double wall_per_step = dt / control.time_scale;
    if (control.paused) {
      sim_clock = now;
    } else if (const double lag = now - sim_clock - wall_per_step; lag > kMaxLagSeconds) {
      // The lag is counted from when the next step fell due, so a step longer than the lag
      // allowed (a soft k, a slowed clock) still comes, and a late wake-up is caught up on.
      status.dropped_steps += static_cast<std::uint64_t>((lag - kMaxLagSeconds) / wall_per_step);
      sim_clock = now - wall_per_step - kMaxLagSeconds;
    }
    // Steps are due up to `now`, but the batch stops at its budget so that
    // snapshots, status and commands keep their rate whatever a step costs.
    const Clock::time_point budget_end =
        busy_start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.batch_seconds));
    auto within_budget = [&](std::uint64_t done) {
      if (done == 0) return true;
      if (options.boundary_every > 0 && world.steps() % options.boundary_every == 0) return false;
      return Clock::now() < budget_end;
    };
    std::uint64_t batch_steps = 0;
    if (control.paused) {
      for (; control.steps_to_run > 0 && within_budget(batch_steps); --control.steps_to_run, ++batch_steps)
        stepper.step();
    } else {
      for (; sim_clock + wall_per_step <= now && within_budget(batch_steps); sim_clock += wall_per_step, ++batch_steps)
        stepper.step();
    }
    const Clock::time_point busy_end = Clock::now();
    const double busy = seconds_between(busy_start, busy_end), wall_end = seconds_between(start, busy_end);
    // The wall time this round covered, at the scale asked in it (set by at_step_boundary, before the batch).
    const double running = control.paused ? 0.0 : sim_clock - clock_before;
    live.add(batch_steps, busy, running, running * control.time_scale);
    line.add(batch_steps, busy, running, running * control.time_scale);
    status.threads = stepper.threads();
    status.crowding_cores = stepper.crowding_cores();
    live.close(sim_clock, wall_end, dt, status);
    LoopStatus line_status = status;
    if (line.close(sim_clock, wall_end, dt, line_status)) {
      if (options.on_status) options.on_status(world, line_status);
      status.dropped_steps = 0;
    }
    if (control.paused && control.steps_to_run > 0) continue;  // asked-for steps run back to back
    // Sleep until a batch of steps is due rather than a single one, and wake
    // the worker threads a little before it: waking a sleeping thread costs
    // more than the batch would otherwise wait for. However far off the next
    // step is, the loop comes round every batch_seconds (commands, snapshots,
    // the status line, stop).
    const double after = seconds_between(start, Clock::now());
    const double next_batch = sim_clock + std::max(wall_per_step, options.batch_seconds);
    const double next_round = now + options.batch_seconds;
    const bool batch_due = !control.paused && next_batch <= next_round;
    const double wake_at = batch_due ? next_batch : next_round;
    const double wait = wake_at - after;
    if (wait > kWakeLeadSeconds) std::this_thread::sleep_for(std::chrono::duration<double>(wait - kWakeLeadSeconds));
    if (batch_due) world.wake_workers();
    if (wait > 0.0)
      std::this_thread::sleep_until(
          start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wake_at)));
  }
}

}  // namespace fishtank
