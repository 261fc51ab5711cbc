#include "server/thread_tuner.h"

namespace fishtank {

ThreadTuner::ThreadTuner(int max_threads) : max_threads_(max_threads), threads_(max_threads) {}

void ThreadTuner::start_window(Phase phase, int threads, double now) {
  phase_ = phase;
  threads_ = threads;
  window_start_ = now;
  busy_ = 0.0;
  steps_ = 0;
}

int ThreadTuner::record(double busy_seconds, std::uint64_t steps, double now) {
  if (max_threads_ <= 1) return threads_;
  busy_ += busy_seconds;
  steps_ += steps;
  const double window = phase_ == Phase::kChosen ? kRemeasureSeconds : kWindowSeconds;
  if (now - window_start_ < window) return threads_;
  if (steps_ == 0) {  // nothing stepped (the loop fell far behind): measure again
    start_window(phase_, threads_, now);
    return threads_;
  }
  const double cost = busy_ / steps_;
  switch (phase_) {
    case Phase::kTimingAll:
      cost_all_ = cost;
      start_window(Phase::kTimingOne, 1, now);
      break;
    case Phase::kTimingOne:
      start_window(Phase::kChosen, cost < cost_all_ ? 1 : max_threads_, now);
      break;
    case Phase::kChosen:
      start_window(Phase::kTimingAll, max_threads_, now);
      break;
  }
  return threads_;
}

}  // namespace fishtank
