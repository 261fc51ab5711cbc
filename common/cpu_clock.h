#pragma once
// CPU time, as opposed to wall time, which also counts the moments a thread
// waited for a core: what work costs on a busy machine.

#include <time.h>

namespace fishtank {

// Seconds on a POSIX CPU clock (CLOCK_PROCESS_CPUTIME_ID, a thread's); 0 where it cannot be read.
inline double cpu_seconds(clockid_t clock) {
  timespec t{};
  return clock_gettime(clock, &t) == 0 ? static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec) : 0.0;
}

// CPU time of the calling thread.
inline double thread_cpu_seconds() { return cpu_seconds(CLOCK_THREAD_CPUTIME_ID); }

}  // namespace fishtank
