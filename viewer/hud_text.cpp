#include "viewer/hud_text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/overlap.h"
#include "common/time_scale.h"

namespace fishtank::viewer {

Freshness figures_freshness(bool connected, double now, double last_update) {
  if (connected) return {};
  if (last_update < 0.0) return {false, "not connected, no update yet"};
  // Whole seconds, so the count ticks up once a second like a clock.
  const long seconds = static_cast<long>(std::floor(std::max(0.0, now - last_update)));
  return {false, "disconnected, last update " + std::to_string(seconds) + " s ago"};
}

std::string threads_text(std::uint32_t stepping, int available) {
  const char* plural = available == 1 ? "" : "s";
  char text[64];
  if (stepping == 0)
    std::snprintf(text, sizeof text, "%d thread%s at most", available, plural);
  else
    std::snprintf(text, sizeof text, "stepping on %u of %d thread%s", stepping, available, plural);
  return text;
}

OverlapText overlap_text(float fraction, float energy_per_ball) {
  char text[96];
  const bool warn = resting_overlap_too_deep(fraction, energy_per_ball);
  std::snprintf(text, sizeof text, "%.1f %% of the smaller radius%s", 100.0 * fraction,
                warn ? ": stiffness too soft for the load" : "");
  return {text, warn};
}

std::string time_scale_text(float time_scale, float time_scale_set, bool paused) {
  if (paused) return "paused";
  if (!(time_scale > 0.0f)) return "-";
  const float set = time_scale_set > 0.0f ? time_scale_set : 1.0f;
  const bool slowed = set < kSlowMotionBelow;
  char text[64];
  if (slow_motion(time_scale, set)) {
    const int n = std::snprintf(text, sizeof text, "slow motion \u00d7%.2f", time_scale);
    if (slowed) std::snprintf(text + n, sizeof text - n, " (\u00d7%.2f set)", set);
    return text;
  }
  if (!slowed) return "real time";
  std::snprintf(text, sizeof text, "\u00d7%.2f as set", set);
  return text;
}

std::string step_text(float dt, float steps_per_contact, float tolerance) {
  if (dt <= 0.0f) return "-";
  char text[128];
  const double ms = 1e3 * dt;
  if (steps_per_contact <= 0.0f)
    std::snprintf(text, sizeof text, "%.3g ms", ms);
  else if (tolerance > 0.0f)
    std::snprintf(text, sizeof text, "%.3g ms, %.0f steps per contact: each collision's e within %g", ms,
                  double(steps_per_contact), double(tolerance));
  else
    std::snprintf(text, sizeof text, "%.3g ms (given), %.1f steps per contact", ms,
                  double(steps_per_contact));
  return text;
}

std::string control_text(bool may_control, const std::string& policy) {
  return (may_control ? "yours (P O R [ ] 1-4): " : "not yours: ") + policy;
}

std::string in_line_text(std::uint32_t ahead) {
  if (ahead == 0) return "observing, next in line for a sphere";
  return "observing, in line for a sphere: " + std::to_string(ahead) + " ahead of you";
}

}  // namespace fishtank::viewer
