#include "server/thread_tuner.h"

#include <algorithm>
#include <cmath>

namespace fishtank {

void ThreadTuner::Estimate::add(double sample, double now) {
  // A sample counts by the time since the estimate's last one, so an estimate
  // timed rarely (the probed count) follows the load as fast as the other.
  const double weight = measured ? 1.0 - std::exp(-(now - at) / kTimeConstant) : 1.0;
  cost += weight * (sample - cost);
  at = now;
  measured = true;
}

ThreadTuner::ThreadTuner(int max_threads)
    : max_threads_(std::max(1, max_threads)), chosen_(max_threads_), threads_(max_threads_) {}

int ThreadTuner::record(double busy_seconds, std::uint64_t steps, double now, Load load) {
  if (max_threads_ <= 1 || steps == 0) return threads_;
  if (load != Load::kMeasure) {
    const int count = load == Load::kOneThread ? 1 : max_threads_;
    if (threads_ == count) estimate(count).add(busy_seconds / steps, now);
    chosen_ = threads_ = count;
    load_decided_ = true;
    return threads_;
  }
  if (load_decided_) {  // measuring again: the other count at once
    load_decided_ = false;
    estimate(threads_).add(busy_seconds / steps, now);
    threads_ = other();
    last_probe_ = now;
    probe_busy_ = 0.0;
    probe_steps_ = 0;
    return threads_;
  }
  if (threads_ == chosen_) {
    estimate(chosen_).add(busy_seconds / steps, now);
  } else {
    // A probe counts as one sample once it has measured enough.
    probe_busy_ += busy_seconds;
    probe_steps_ += steps;
    if (probe_busy_ < kProbeBusySeconds) return threads_;
    estimate(threads_).add(probe_busy_ / probe_steps_, now);
  }
  const double margin = other() == 1 ? kHysteresisToOne : kHysteresisToAll;
  if (one_.measured && all_.measured && estimate(other()).cost < (1.0 - margin) * estimate(chosen_).cost)
    chosen_ = other();
  threads_ = chosen_;
  const double backoff = estimate(other()).measured
                             ? std::clamp(estimate(other()).cost / estimate(chosen_).cost, 1.0, kMaxProbeBackoff)
                             : 1.0;
  if (now - last_probe_ >= kProbeSeconds * backoff) {
    threads_ = other();
    last_probe_ = now;
    probe_busy_ = 0.0;
    probe_steps_ = 0;
  }
  return threads_;
}

}  // namespace fishtank
