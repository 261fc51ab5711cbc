#include "server/realtime_loop.h"

#include <chrono>
#include <thread>

namespace fishtank {

namespace {
using Clock = std::chrono::steady_clock;
// Past this much lag the loop stops trying to catch up and runs in slow motion
// instead, rather than stalling everything in a burst of catch-up steps.
constexpr double kMaxLagSeconds = 0.25;
}  // namespace

void run_realtime(World& world, const LoopOptions& options, const std::atomic<bool>& stop) {
  const double dt = world.dt();
  const Clock::time_point start = Clock::now();
  double sim_clock = 0.0;  // simulated seconds owed to the wall clock so far
  LoopStatus status;
  Clock::time_point window_start = start;
  std::uint64_t window_steps = 0;
  double window_busy = 0.0;

  while (!stop.load(std::memory_order_relaxed)) {
    const double now = std::chrono::duration<double>(Clock::now() - start).count();
    if (options.duration > 0.0 && now >= options.duration) break;
    if (now - sim_clock > kMaxLagSeconds) {
      status.dropped_steps += static_cast<std::uint64_t>((now - sim_clock - kMaxLagSeconds) / dt);
      sim_clock = now - kMaxLagSeconds;
    }
    const Clock::time_point busy_start = Clock::now();
    if (options.at_step_boundary) options.at_step_boundary(world, status);
    while (sim_clock + dt <= now) {
      world.step();
      sim_clock += dt;
      ++window_steps;
    }
    const Clock::time_point busy_end = Clock::now();
    window_busy += std::chrono::duration<double>(busy_end - busy_start).count();

    const double window = std::chrono::duration<double>(busy_end - window_start).count();
    if (window >= options.status_interval) {
      status.steps_per_s = window_steps / window;
      status.load = window_busy / window;
      if (options.on_status) options.on_status(world, status);
      window_start = busy_end;
      window_steps = 0;
      status.dropped_steps = 0;
      window_busy = 0.0;
    }
    // Sleep until a batch of steps is due rather than a single one: waking the
    // worker threads costs tens of microseconds on a virtual machine, paid
    // once per batch instead of once per step.
    const double next_batch = sim_clock + std::max(dt, options.batch_seconds);
    const double wait = next_batch - std::chrono::duration<double>(Clock::now() - start).count();
    if (wait > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
  }
}

}  // namespace fishtank
