#include "server/physics/prefetch_plan.h"

#include <algorithm>

namespace fishtank {

PrefetchPlan prefetch_plan(const NeighbourList& list, std::uint32_t n, bool beyond_cache) {
  PrefetchPlan plan;
  plan.beyond_cache = beyond_cache;
  plan.remote_rows = list.remote_rows();
  plan.balls = n;
  plan.batches = (n + kStepBatch - 1) / kStepBatch;
  plan.reach = list.batch_reach();
  return plan;
}

// Neighbouring chunks' threads read each other's edge rows, and each such line
// comes by a transfer between cores. So a chunk asks for them ahead, while
// batches that do not need them run: the rows below its first ball at once
// (running first the batches after those that read them), the rows around
// its last ball over the few batches before. Larger ranges are left to the hardware.
EdgeFetches edge_fetches(const PrefetchPlan& plan, std::uint32_t begin, std::uint32_t end) {
  constexpr std::uint32_t kBelowWindow = 2, kAboveWindow = 4;  // batches
  constexpr std::uint32_t kMostRowsPerBall = 4;
  const BatchReach* reach = plan.reach;
  const std::uint32_t first = begin / kStepBatch, last = (end + kStepBatch - 1) / kStepBatch;
  const std::uint32_t n = plan.balls, batches = plan.batches;
  EdgeFetches edges;
  RowFetch* fetch = edges.rows;
  const auto add = [&](RowFetch f) {
    if (f.rows_begin < f.rows_end &&
        f.rows_end - f.rows_begin <= (f.end_batch - f.first_batch) * kStepBatch * kMostRowsPerBall)
      *fetch++ = f;
  };
  if (begin > 0) {
    std::uint32_t lowest = begin, lead = first;  // lead: the first batch that reads no row below
    for (std::uint32_t b = first; b < last; ++b) lowest = std::min(lowest, reach[b].lowest);
    while (lead < last && reach[lead].lowest < begin) ++lead;
    if (lead == last) lead = first;  // every batch reads below: no batch to run meanwhile
    const std::uint32_t lead_end = std::min(last, lead + kBelowWindow);
    if (lead > first) edges.lead_begin = lead * kStepBatch, edges.lead_end = std::min(end, lead_end * kStepBatch);
    add({lowest, begin, lead, lead_end});
  }
  if (end < n) {
    std::uint32_t lowest = end, highest = end - 1;  // [lowest, highest]: rows both threads read
    for (std::uint32_t b = last; b < batches; ++b) lowest = std::min(lowest, reach[b].lowest);
    for (std::uint32_t b = first; b < last; ++b) highest = std::max(highest, reach[b].highest);
    std::uint32_t reader = first;  // this chunk's first batch that reads them
    while (reader + 1 < last && reach[reader].highest < lowest) ++reader;
    add({lowest, highest + 1, std::max(first, reader - std::min(reader, kAboveWindow)), std::max(reader, first + 1)});
  }
  return edges;
}

}  // namespace fishtank
