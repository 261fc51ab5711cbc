#pragma once
// What the SIMD step asks memory for ahead, beyond the caches (World::beyond_cache):
// each group its share of the batch kPrefetchBatches on, and of the rows the lists
// name far away or that the other thread writes (PrefetchPlan). Shared by both
// kernel files through kernels_simd_ball.h, with internal linkage as there.

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "common/float4.h"
#include "server/physics/kernels.h"
#include "server/physics/prefetch_plan.h"

namespace fishtank {
namespace {

// Beyond the caches, rows gathered in group order arrive late if left to the
// hardware's prefetcher, so each group asks for its share of the rows and
// lists kPrefetchBatches ahead, enough batches to cover memory latency.
constexpr std::uint32_t kPrefetchBatches = 4;

// Lines read again by later groups (a batch's rows are its neighbours'
// neighbours) or touched once this step (records, lists, next-step rows): the
// latter are asked for non-temporally, so they do not evict the former.
enum class Reuse { kAgain, kOnce };

// Asks for the cache line `bytes` past `base`. A prefetch never faults, so the address may lie past
// an array's end: formed as an integer, not by pointer arithmetic.
template <Reuse kReuse>
inline void prefetch(const void* base, std::size_t bytes) {
  constexpr int kLocality = kReuse == Reuse::kAgain ? 3 : 0;  // 0: prefetchnta
  __builtin_prefetch(reinterpret_cast<const void*>(reinterpret_cast<std::uintptr_t>(base) + bytes), 0, kLocality);
}

// The rows a ball's neighbours read (position, half-step velocity now and a step before), `bytes` in.
inline void prefetch_rows(const StepArrays& s, std::size_t bytes) {
  prefetch<Reuse::kAgain>(s.pos, bytes);
  prefetch<Reuse::kAgain>(s.vel_half, bytes);
  prefetch<Reuse::kAgain>(s.vel_half_before, bytes);
}

// This group's share of the rows, records and lists of the batch
// kPrefetchBatches ahead, and of that batch's remote rows.
template <std::uint32_t kCount>
[[gnu::always_inline]] inline void prefetch_batch_ahead(const StepContext& ctx, const GroupLists& lists,
                                                        std::uint32_t batch, std::uint32_t share) {
  const StepArrays& s = ctx.arrays;
  const PrefetchPlan& plan = ctx.plan;
  const std::size_t ahead = std::size_t(batch) + kPrefetchBatches * kStepBatch;
  const std::size_t rows = (ahead + share * kCount) * sizeof(Float4);
  for (std::size_t line = rows; line < rows + kCount * sizeof(Float4); line += kCacheLineBytes) {
    prefetch_rows(s, line);
    prefetch<Reuse::kOnce>(lists.records, line);  // 16 bytes per ball too, in the batch's group order
    prefetch<Reuse::kOnce>(s.pos_next, line);
    prefetch<Reuse::kOnce>(s.vel_half_next, line);
  }
  // A group's blocks take about eight entries per lane (a settled pile's neighbours, rounded up to a block).
  constexpr std::size_t kListBytesPerLane = 8 * sizeof(std::uint32_t);
  const std::size_t block = ahead * lists.stride * sizeof(std::uint32_t);
  for (std::size_t line = share * kCount * kListBytesPerLane; line < (share + 1) * kCount * kListBytesPerLane;
       line += kCacheLineBytes)
    prefetch<Reuse::kOnce>(lists.neighbours, block + line);
  const std::size_t remote_batch = ahead / kStepBatch;
  if (remote_batch >= plan.batches) return;
  const RemoteRows& remote = plan.remote_rows[remote_batch];
  for (std::uint32_t k = share; k < remote.count; k += kStepBatch / kCount)
    prefetch_rows(s, std::size_t(remote.rows[k]) * sizeof(Float4));
}

inline bool in_window(const RowFetch& f, std::uint32_t batch) { return batch >= f.first_batch && batch < f.end_batch; }

// Asks for this group's share of a RowFetch's cache lines, when `batch` (a
// batch number) is in its window; `share` is the group's place in its batch.
template <std::uint32_t kCount>
[[gnu::always_inline]] inline void fetch_rows(const StepArrays& s, const RowFetch& f, std::uint32_t batch,
                                              std::uint32_t share) {
  if (!in_window(f, batch)) return;
  constexpr std::size_t kGroups = kStepBatch / kCount;
  const std::size_t first_line = f.rows_begin * sizeof(Float4) / kCacheLineBytes;
  const std::size_t end_line = (f.rows_end * sizeof(Float4) + kCacheLineBytes - 1) / kCacheLineBytes;
  const std::size_t groups = (f.end_batch - f.first_batch) * kGroups;
  const std::size_t per_group = (end_line - first_line + groups - 1) / groups;
  const std::size_t from = first_line + ((batch - f.first_batch) * kGroups + share) * per_group;
  for (std::size_t line = from; line < std::min(end_line, from + per_group); ++line)
    prefetch_rows(s, line * kCacheLineBytes);
}

}  // namespace
}  // namespace fishtank
