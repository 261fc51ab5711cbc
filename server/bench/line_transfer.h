#pragma once
// Where the host placed this machine's cores, as a time: a cache line's trip
// from one core to another. On a shared virtual machine two virtual cores may
// sit close or apart, and the placement changes from hour to hour; a scene whose threads share lines, as
// a small one does along its chunks' edges, runs faster in the first case.
// The benchmarks print it so that a run says which case it measured.

#include <optional>
#include <vector>

namespace fishtank {

struct LineTransfer {
  int cpu_a = 0, cpu_b = 0;  // the first two CPUs this process may run on
  double ns = 0.0;           // one way, the mean of round_trips round trips
};

// Passes a flag back and forth `round_trips` times between two threads pinned
// to the first two of `cpus` (by default the calling thread's affinity, which a
// stepping pool narrows to one CPU: pass World::cpus() there). Empty with fewer
// than two CPUs, or where a thread cannot be pinned.
std::optional<LineTransfer> time_line_transfer(int round_trips = 200000);
std::optional<LineTransfer> time_line_transfer(const std::vector<int>& cpus, int round_trips = 200000);

}  // namespace fishtank
