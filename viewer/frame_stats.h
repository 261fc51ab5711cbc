#pragma once
// Frame rate, frame time and CPU time per frame, each measured over the last
// second of real frames (SPEC 5.1: measured, not estimated), plus totals for
// the summary printed at exit. The totals count only frames that drew the
// scene, so start-up frames before the first snapshot do not flatter them.

#include <cstdint>
#include <deque>

namespace fishtank::viewer {

class FrameStats {
 public:
  // Once per frame: when it ended, the CPU seconds it spent outside GL calls,
  // and whether it drew the scene.
  void frame_done(double now, double cpu_seconds, bool scene);

  float fps() const { return fps_; }
  float frame_ms() const { return frame_ms_; }
  float cpu_ms() const { return cpu_ms_; }

  std::uint64_t total_frames() const { return total_frames_; }
  // Every frame, with the scene or without it (waiting for a server): the summary of a viewer that never drew
  // one.
  std::uint64_t all_frames() const { return all_frames_; }
  double all_seconds() const { return all_last_ - all_first_; }
  // A minimised window drew nothing from `from` to `to`: that time is left out of the summary's rate.
  void not_drawn(double from, double to);
  double minimised_seconds() const { return minimised_; }
  // First to last scene frame, less the time minimised in between.
  double total_seconds() const { return last_ - first_ - minimised_; }
  double mean_cpu_ms() const {
    return total_frames_ ? 1e3 * total_cpu_ / static_cast<double>(total_frames_) : 0.0;
  }

 private:
  struct Sample {
    double end;
    double cpu;
  };
  std::deque<Sample> window_;  // frames that ended in the last second
  float fps_ = 0.0f, frame_ms_ = 0.0f, cpu_ms_ = 0.0f;
  std::uint64_t total_frames_ = 0, all_frames_ = 0;
  double total_cpu_ = 0.0;
  double first_ = 0.0, last_ = 0.0, all_first_ = 0.0, all_last_ = 0.0;
  double minimised_ = 0.0;
};

}  // namespace fishtank::viewer
