#pragma once
// One time base for the whole viewer: seconds on the steady clock, shared by
// the net thread (snapshot arrival, round trips) and the render thread
// (frame times, interpolation), so their times can be compared directly.
// And the thread's CPU clock, for the cost of a frame's work outside GL.

#include <time.h>

#include <chrono>

namespace fishtank::viewer {

inline double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// CPU time of the calling thread: what a frame's own work costs, unlike wall
// time, which also counts the moments the thread waited for a core.
inline double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace fishtank::viewer
