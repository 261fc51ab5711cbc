#pragma once
// Picks how many worker threads a paced server steps with, by measurement.
//
// Run flat out, more cores always help (technical report 6.1). Paced to the
// wall clock, a batch of a few short steps starts after the workers have sat
// idle for milliseconds, and on a virtual machine a second core can then cost
// more than it saves (a 6000-ball tank: 23 % load on one thread, 26 % on two).
// So the tuner times one window with every thread and one with a single
// thread, keeps the cheaper per step, and measures both again now and then
// because the world changes (balls poured in, a player ploughing through).
// Results never depend on the thread count (the state is bit-identical), so
// switching is invisible except in the load.

#include <cstdint>

namespace fishtank {

class ThreadTuner {
 public:
  // Seconds of wall time per measuring window, and between measurements.
  static constexpr double kWindowSeconds = 0.5;
  static constexpr double kRemeasureSeconds = 20.0;

  explicit ThreadTuner(int max_threads);

  // Records one batch: wall seconds spent stepping, steps done, and the wall
  // clock (seconds) at its end. Returns the thread count for the next batch.
  int record(double busy_seconds, std::uint64_t steps, double now);
  int threads() const { return threads_; }

 private:
  enum class Phase { kTimingAll, kTimingOne, kChosen };
  void start_window(Phase phase, int threads, double now);

  int max_threads_;
  int threads_;
  Phase phase_ = Phase::kTimingAll;
  double window_start_ = 0.0;
  double busy_ = 0.0;
  std::uint64_t steps_ = 0;
  double cost_all_ = 0.0;  // seconds per step with every thread, last measured
};

}  // namespace fishtank
