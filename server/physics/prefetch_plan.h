#pragma once
// What a SIMD step asks memory for ahead of use (PrefetchPlan and EdgeFetches,
// kernels.h), from the lists of the last build. Results never depend on it.

#include <cstdint>

#include "server/physics/broadphase.h"
#include "server/physics/kernels.h"

namespace fishtank {

// The step's plan for n balls: rows ahead and the remote rows only beyond the caches.
PrefetchPlan prefetch_plan(const NeighbourList& list, std::uint32_t n, bool beyond_cache);

// The edge rows that chunk [begin, end) shares with its neighbours' threads: the SIMD step asks for its own.
EdgeFetches edge_fetches(const PrefetchPlan& plan, std::uint32_t begin, std::uint32_t end);

}  // namespace fishtank
