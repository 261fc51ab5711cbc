#include "viewer/frame_stats.h"

namespace fishtank::viewer {

void FrameStats::frame_done(double now, double cpu_seconds, bool scene) {
  if (all_frames_++ == 0) all_first_ = now;
  all_last_ = now;
  if (scene) {
    if (total_frames_++ == 0) first_ = now;
    last_ = now;
    total_cpu_ += cpu_seconds;
  }

  window_.push_back({now, cpu_seconds});
  // Keep one frame older than a second: its end is where the oldest counted frame began.
  while (window_.size() > 2 && window_[1].end <= now - 1.0) window_.pop_front();
  const auto intervals = static_cast<double>(window_.size() - 1);
  const double span = now - window_.front().end;
  if (intervals < 1.0 || span <= 0.0) return;
  fps_ = static_cast<float>(intervals / span);
  frame_ms_ = static_cast<float>(1e3 * span / intervals);
  double cpu = 0.0;
  for (std::size_t i = 1; i < window_.size(); ++i) cpu += window_[i].cpu;
  cpu_ms_ = static_cast<float>(1e3 * cpu / intervals);
}

void FrameStats::not_drawn(double from, double to) {
  // Before the first scene frame the summary's span has not begun.
  if (total_frames_ > 0 && to > from) minimised_ += to - from;
}

}  // namespace fishtank::viewer
