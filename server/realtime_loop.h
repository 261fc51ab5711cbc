#pragma once
// Steps a world paced to the wall clock: simulated time follows real time at
// the fixed dt. Each batch of steps keeps to a wall-clock budget, so when the
// physics cannot keep real time the world runs in slow motion while
// snapshots and commands keep their rate. Reports steps actually done per
// second, the load (the busy fraction of the wall time) and the time scale.
// It picks the thread count the steps use as the machine's load changes
// (TunedStepper), which the benchmark's unpaced steps use too.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>

#include "server/machine_load.h"
#include "server/physics/world.h"
#include "server/thread_tuner.h"

namespace fishtank {

// Steps a world, choosing before each step between every worker thread and one
// as the machine's load and the steps' measured cost say (ThreadTuner,
// MachineLoad); untuned, on the world's thread limit. Results never depend on it.
class TunedStepper {
 public:
  TunedStepper(World& world, bool tune);

  World& world() const { return world_; }
  void step();
  // The threads the steps use: the tuner's choice between its probes, one where the balls are too few to split.
  int threads() const { return std::min(tuner_ ? tuner_->chosen() : world_.thread_limit(), world_.stepping_threads()); }
  // While tuning: the cores work in other sessions keeps busy (MachineLoad::crowding), below 0 until measured.
  double crowding_cores() const { return tuner_ && machine_load_.measured() ? machine_load_.crowding() : -1.0; }
  std::uint64_t steps_on_one_thread() const { return one_thread_steps_; }

 private:
  World& world_;
  std::optional<ThreadTuner> tuner_;
  MachineLoad machine_load_;
  std::chrono::steady_clock::time_point epoch_;
  std::uint64_t one_thread_steps_ = 0;
};

// Its rates (steps_per_s, load, time_scale) cover the last status interval in
// on_status, and the last second (or the interval, if shorter) in at_step_boundary.
struct LoopStatus {
  double steps_per_s = 0.0;
  int threads = 1;                  // worker threads the steps use now (see ThreadTuner)
  double crowding_cores = -1.0;     // cores work in other sessions keeps busy; below 0 unknown
  double load = 0.0;                // 0..1: time the loop spent stepping (and at its boundaries) / wall time
  std::uint64_t dropped_steps = 0;  // steps skipped because the machine fell behind, in the last interval
  // Simulated seconds per wall second while not paused: below the scale people
  // asked for, the physics cannot keep up and the world runs in slow motion.
  double time_scale = 1.0;
  // Simulated time done / asked for (1: none asked, paused): below 1 it fell short,
  // also where the scale asked changed within the window.
  double pace_kept = 1.0;
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
  // Nonzero: a batch also ends at every step that is a multiple of it, so at_step_boundary sees that step
  // (a recording's frames).
  std::uint64_t boundary_every = 0;
};

void run_realtime(TunedStepper& stepper, const LoopOptions& options, const std::atomic<bool>& stop);

}  // namespace fishtank
