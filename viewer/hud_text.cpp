#include "viewer/hud_text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

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

std::string time_scale_text(float time_scale) {
  if (!(time_scale > 0.0f)) return "-";
  if (!slow_motion(time_scale)) return "real time";
  char text[40];
  std::snprintf(text, sizeof text, "slow motion \u00d7%.2f", time_scale);
  return text;
}

}  // namespace fishtank::viewer
