#pragma once
// Steps a world paced to the wall clock: simulated time follows real time at
// the fixed dt. Each batch of steps keeps to a wall-clock budget, so when the
// physics cannot keep real time the world runs in slow motion while
// snapshots and commands keep their rate. Reports steps actually done per
// second, the load (the busy fraction of the wall time) and the time scale.

#include <atomic>
#include <functional>

#include "server/physics/world.h"

namespace fishtank {

struct LoopStatus {
  double steps_per_s = 0.0;
  int threads = 1;                  // worker threads the steps use now (see ThreadTuner)
  double crowding_cores = -1.0;     // cores work in other sessions keeps busy; below 0 unknown
  double load = 0.0;                // 0..1: time spent stepping / wall time
  std::uint64_t dropped_steps = 0;  // steps skipped because the machine fell behind, in the last interval
  // Simulated seconds per wall second over the last interval: below 1 the
  // physics cannot keep real time and the world runs in slow motion.
  double time_scale = 1.0;
};

// What people ask of the loop: pause, a few steps while paused, a slower
// clock. Written between batches (at_step_boundary, on the loop's thread),
// read by the loop before each batch.
struct RunControl {
  bool paused = false;
  std::uint64_t steps_to_run = 0;  // while paused: steps asked for and not yet done
  // Simulated seconds per wall second asked for, 0.1 .. 1; the loop's
  // LoopStatus::time_scale is what it achieves (lower when overloaded).
  double time_scale = 1.0;
};

struct LoopOptions {
  double duration = 0.0;  // seconds; 0 runs until stop is set
  double status_interval = 1.0;
  // Steps run in batches of this much simulated time, and a batch spends at
  // most this much wall time stepping (beyond its first step): waking the
  // worker threads is paid once per batch, and at_step_boundary runs once per
  // batch, so it must not be longer than the interval between snapshots.
  double batch_seconds = 0.004;
  // Called on the loop's thread between steps, once per status interval.
  std::function<void(const World&, const LoopStatus&)> on_status;
  // Called on the loop's thread before each batch (at least every
  // batch_seconds, plus one step), with the latest status: the one place where
  // others may change the world (commands) or read it (snapshots).
  std::function<void(World&, const LoopStatus&)> at_step_boundary;
  // Read before each batch, after at_step_boundary; null: always real time.
  RunControl* control = nullptr;
};

void run_realtime(World& world, const LoopOptions& options, const std::atomic<bool>& stop);

}  // namespace fishtank
