#include "viewer/net/snapshot_buffer.h"

#include <algorithm>

namespace fishtank::viewer {
namespace {

constexpr double kSmoothing = 0.05;      // weight of one new sample
constexpr double kDelayIntervals = 1.5;  // render this many intervals behind
constexpr double kMinDelay = 0.02;       // seconds
constexpr double kMaxDelay = 0.25;

}  // namespace

void SnapshotBuffer::clear() {
  std::lock_guard lock(mutex_);
  snapshots_.clear();
  offset_ = 0.0;
  mean_interval_ = 0.0;
}

void SnapshotBuffer::push(std::shared_ptr<const Snapshot> s) {
  std::lock_guard lock(mutex_);
  double sample = s->received - s->sim_time;
  if (snapshots_.empty()) {
    offset_ = sample;
  } else {
    // A late arrival says little (the network was slow); the earliest one is
    // the best guess of the true offset. Drifting up slowly lets the estimate
    // follow a server that falls behind real time.
    offset_ = sample < offset_ ? sample : offset_ + kSmoothing * (sample - offset_);
    double interval = s->sim_time - snapshots_.back()->sim_time;
    if (interval > 0.0)
      mean_interval_ =
          mean_interval_ == 0.0 ? interval : mean_interval_ + kSmoothing * (interval - mean_interval_);
  }
  snapshots_.push_back(std::move(s));
  if (snapshots_.size() > kKept) snapshots_.pop_front();
}

double SnapshotBuffer::render_delay() const {
  std::lock_guard lock(mutex_);
  return std::clamp(kDelayIntervals * mean_interval_, kMinDelay, kMaxDelay);
}

bool SnapshotBuffer::frame_at(double now, RenderPair& out) const {
  double delay = render_delay();
  std::lock_guard lock(mutex_);
  if (snapshots_.empty()) return false;
  double t = now - offset_ - delay;
  // Newest first: the pair is usually at the end.
  for (std::size_t i = snapshots_.size() - 1; i > 0; --i) {
    const auto& a = snapshots_[i - 1];
    const auto& b = snapshots_[i];
    if (t >= a->sim_time) {
      out.from = a;
      out.to = b;
      double span = b->sim_time - a->sim_time;
      out.alpha = span > 0.0 ? static_cast<float>(std::min((t - a->sim_time) / span, 1.0)) : 1.0f;
      if (t >= b->sim_time) out.from = b, out.alpha = 0.0f;
      return true;
    }
  }
  out.from = out.to = snapshots_.front();  // older than anything kept: hold the oldest
  out.alpha = 0.0f;
  return true;
}

std::shared_ptr<const Snapshot> SnapshotBuffer::newest() const {
  std::lock_guard lock(mutex_);
  return snapshots_.empty() ? nullptr : snapshots_.back();
}

}  // namespace fishtank::viewer
