#pragma once
// What a SIMD step asks memory for ahead of use (PrefetchPlan, kernels.h), from
// the lists of the last build. Results never depend on it.

#include <cstdint>

#include "server/physics/broadphase.h"
#include "server/physics/kernels.h"

namespace fishtank {

// The step's plan for n balls: rows ahead and the remote rows only beyond the caches.
PrefetchPlan prefetch_plan(const NeighbourList& list, std::uint32_t n, bool beyond_cache);

// Adds to plan the edge rows that chunk [begin, end) shares with its neighbours' threads.
void add_edge_fetches(PrefetchPlan& plan, const NeighbourList& list, std::uint32_t n, std::uint32_t begin,
                      std::uint32_t end);

}  // namespace fishtank
