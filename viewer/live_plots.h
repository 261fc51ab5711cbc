#pragma once
// The figures the live-plot panel draws, over the last kWindowSeconds: one
// sample per snapshot received, older ones dropped. Kept apart from ImGui so
// it can be tested.

#include <cstddef>
#include <deque>
#include <vector>

#include "viewer/net/snapshot.h"

namespace fishtank::viewer {

class LivePlots {
 public:
  static constexpr double kWindowSeconds = 30.0;
  enum Series { kinetic_energy, contacts, steps_per_s, time_scale, series_count };

  // Adds s unless it was added already (the same tick of the same connection); drops what is too old.
  void add(const Snapshot& s);
  void clear() { samples_.clear(); }
  // Oldest first, over the window.
  const std::vector<float>& series(Series which);
  // Seconds the samples span (at most kWindowSeconds).
  double span_seconds() const;
  float newest(Series which) const { return samples_.empty() ? 0.0f : samples_.back().values[which]; }

 private:
  struct Sample {
    double received;
    std::uint64_t tick;
    float values[series_count];
  };
  std::deque<Sample> samples_;
  std::vector<float> scratch_;
};

}  // namespace fishtank::viewer
