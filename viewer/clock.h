#pragma once
// One time base for the whole viewer: seconds on the steady clock, shared by
// the net thread (snapshot arrival, round trips) and the render thread
// (frame times, interpolation), so their times can be compared directly.

#include <chrono>

namespace fishtank::viewer {

inline double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace fishtank::viewer
