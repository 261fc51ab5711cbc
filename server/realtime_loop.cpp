#include "server/realtime_loop.h"

#include <chrono>
#include <thread>

#include "server/thread_tuner.h"

namespace fishtank {

namespace {
using Clock = std::chrono::steady_clock;
// Past this much lag the loop stops trying to catch up and runs in slow motion
// instead, rather than stalling everything in a burst of catch-up steps.
constexpr double kMaxLagSeconds = 0.25;
// How long before a batch the workers are woken: enough for a sleeping thread
// to be scheduled on this virtual machine, well inside the pool's 1 ms of polling.
constexpr double kWakeLeadSeconds = 0.0003;
}  // namespace

void run_realtime(World& world, const LoopOptions& options, const std::atomic<bool>& stop) {
  const double dt = world.dt();
  const Clock::time_point start = Clock::now();
  double sim_clock = 0.0;  // simulated seconds owed to the wall clock so far
  LoopStatus status;
  Clock::time_point window_start = start;
  std::uint64_t window_steps = 0;
  double window_busy = 0.0;
  ThreadTuner tuner(world.threads());
  world.set_thread_limit(tuner.threads());

  while (!stop.load(std::memory_order_relaxed)) {
    const double now = std::chrono::duration<double>(Clock::now() - start).count();
    if (options.duration > 0.0 && now >= options.duration) break;
    if (now - sim_clock > kMaxLagSeconds) {
      status.dropped_steps += static_cast<std::uint64_t>((now - sim_clock - kMaxLagSeconds) / dt);
      sim_clock = now - kMaxLagSeconds;
    }
    const Clock::time_point busy_start = Clock::now();
    if (options.at_step_boundary) options.at_step_boundary(world, status);
    std::uint64_t batch_steps = 0;
    for (; sim_clock + dt <= now; sim_clock += dt, ++batch_steps) world.step();
    const Clock::time_point busy_end = Clock::now();
    const double busy = std::chrono::duration<double>(busy_end - busy_start).count();
    window_busy += busy;
    window_steps += batch_steps;
    world.set_thread_limit(tuner.record(busy, batch_steps, std::chrono::duration<double>(busy_end - start).count()));
    status.threads = world.thread_limit();

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
    // Sleep until a batch of steps is due rather than a single one, and wake
    // the worker threads a little before it: waking a sleeping thread costs
    // tens to hundreds of microseconds on a virtual machine, which the batch
    // would otherwise wait for.
    const double next_batch = sim_clock + std::max(dt, options.batch_seconds);
    const double wait = next_batch - std::chrono::duration<double>(Clock::now() - start).count();
    if (wait > kWakeLeadSeconds) std::this_thread::sleep_for(std::chrono::duration<double>(wait - kWakeLeadSeconds));
    world.wake_workers();
    if (wait > 0.0)
      std::this_thread::sleep_until(
          start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(next_batch)));
  }
}

}  // namespace fishtank
