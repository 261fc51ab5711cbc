#include "viewer/live_plots.h"

namespace fishtank::viewer {

void LivePlots::add(const Snapshot& s) {
  if (!samples_.empty() && samples_.back().tick == s.tick && samples_.back().received == s.received) return;
  samples_.push_back(
      {s.received,
       s.tick,
       {s.kinetic_energy_per_ball, static_cast<float>(s.contacts), s.steps_per_s, s.time_scale}});
  while (s.received - samples_.front().received > kWindowSeconds) samples_.pop_front();
}

const std::vector<float>& LivePlots::series(Series which) {
  scratch_.clear();
  for (const Sample& sample : samples_) scratch_.push_back(sample.values[which]);
  return scratch_;
}

double LivePlots::span_seconds() const {
  return samples_.size() < 2 ? 0.0 : samples_.back().received - samples_.front().received;
}

}  // namespace fishtank::viewer
