#pragma once
// Picks how many worker threads a world steps with, by measurement.
//
// On a busy machine a preempted worker holds up its pass, and one thread can
// step faster than all. Where the machine's load decides (MachineLoad), the
// tuner follows it: one thread while work in other sessions leaves no core for
// each, every thread while work in the server's own session shares the cores
// per thread. Step timings there are too noisy to choose by: they follow where
// the kernel places the threads. Otherwise the tuner keeps a running cost
// estimate of a step pass (list rebuilds left out) on every thread and on one (time constant kTimeConstant),
// steps with the cheaper, and now and then times a few steps with the other (a probe).
// Results never depend on the thread count: switching shows only in speed.

#include <cstdint>

namespace fishtank {

class ThreadTuner {
 public:
  static constexpr double kTimeConstant = 0.1;
  // Seconds between probes while the two counts cost about the same; up to
  // kMaxProbeBackoff times longer while the other is that much dearer, so a
  // count that stalls (many busy processes) is rarely tried.
  static constexpr double kProbeSeconds = 0.1;
  static constexpr double kMaxProbeBackoff = 5.0;
  // A probe lasts until it has measured this much stepping.
  static constexpr double kProbeBusySeconds = 0.001;
  // Hysteresis against swapping back and forth; more to go to every thread, whose cost varies more.
  static constexpr double kHysteresisToOne = 0.05;
  static constexpr double kHysteresisToAll = 0.15;

  explicit ThreadTuner(int max_threads);

  // What the machine's load says (MachineLoad): nothing, or the count to step with, unprobed.
  enum class Load { kMeasure, kOneThread, kEveryThread };

  // Records steps done: wall seconds their step passes took, steps, and the wall clock
  // (seconds) at their end. Returns the thread count for the next steps. When
  // the load stops deciding, the other count is probed at once.
  int record(double busy_seconds, std::uint64_t steps, double now, Load load = Load::kMeasure);
  // The count the next steps use.
  int threads() const { return threads_; }
  // The count the estimates favour (threads() differs from it during a probe).
  int chosen() const { return chosen_; }

 private:
  // Seconds per step, averaged over the last kTimeConstant seconds or so.
  struct Estimate {
    double cost = 0.0;
    double at = 0.0;  // wall clock of the last sample it took in
    bool measured = false;
    void add(double sample, double now);
  };
  Estimate& estimate(int threads) { return threads == 1 ? one_ : all_; }
  int other() const { return chosen_ == 1 ? max_threads_ : 1; }

  int max_threads_;
  int chosen_;
  int threads_;
  double last_probe_ = 0.0;
  bool load_decided_ = false;  // the last record()'s load chose the count
  double probe_busy_ = 0.0;    // the running probe's stepping so far
  std::uint64_t probe_steps_ = 0;
  Estimate one_, all_;
};

}  // namespace fishtank
