#pragma once
// The SIMD neighbour-list build, shared by both kernel files (kernels_simd_ball.h):
// candidates tested four at a time, each list ordered nearest first as the scalar
// twin's is, each batch's balls grouped by length and contacts, and the rows far
// from a batch noted for the step's prefetch. Internal linkage, as there.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/simd/sse_float4.h"
#include "server/physics/broadphase.h"

namespace fishtank {
namespace {

using simd::F4;
using simd::M4;

// Set bits of a 4-bit mask (the SSE4.1 build has no popcnt instruction:
// __builtin_popcount would be a library call).
constexpr std::uint8_t kSetBits[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};

// Ball i's list into found (at most b.stride entries) with each entry's key
// (order_nearest_first); returns the true count. Four consecutive candidates
// per test, packed with a byte shuffle: no branch per candidate to mispredict.
inline std::uint32_t list_of(const ListBuild& b, std::uint32_t i, std::uint32_t* found, float* keys) {
  static constexpr std::uint8_t kFirstLanes[5] = {0x0, 0x1, 0x3, 0x7, 0xf};  // the first k lanes' bits
  const float *const xs = b.x, *const ys = b.y, *const zs = b.z, *const rs = b.r;
  const std::uint32_t stride = b.stride;
  const F4 xi = F4::splat(xs[i]), yi = F4::splat(ys[i]), zi = F4::splat(zs[i]), ri = F4::splat(rs[i]);
  const F4 skin = F4::splat(b.skin);
  std::uint32_t count = 0;
  for_each_neighbour_range(b, i, [&](std::uint32_t j_begin, std::uint32_t j_end) {
    for (std::uint32_t j = j_begin; j < j_end; j += 4) {  // may read up to 3 ghosts past the end
      const F4 dx = F4::loadu(xs + j) - xi, dy = F4::loadu(ys + j) - yi, dz = F4::loadu(zs + j) - zi;
      const F4 d2 = dx * dx + dy * dy + dz * dz, reach = F4::loadu(rs + j) + ri, cutoff = reach + skin;
      const F4 key = d2 - reach * reach;
      // Lanes past the range's end, and ball i itself, are not neighbours.
      int within = bits(d2 < cutoff * cutoff) & kFirstLanes[std::min(j_end - j, 4u)];
      if (i - j < 4) within &= ~(1 << (i - j));
      if (count + 4 > stride) {  // nearly full: one by one, counting on so the caller can grow the list
        alignas(16) float lane_keys[4];
        key.storeu(lane_keys);
        for (std::uint32_t lane = 0; lane < 4; ++lane, within >>= 1)
          if (within & 1) {
            if (count < stride) found[count] = j + lane, keys[count] = lane_keys[lane];
            ++count;
          }
        continue;
      }
      // No branch on whether any was found: it would be mispredicted often.
      compress_store(simd::I4::iota(j), within, found + count);
      compress_store(key, within, keys + count);
      count += kSetBits[within];
    }
  });
  return count;
}

// The scalar twin's order (kernels_scalar.cpp), four places per instruction:
// an entry's place is the number of smaller keys, ties taking the next free
// place in the order found. Returns how many touch; reads keys past count.
inline std::uint32_t order_nearest_first(const float* keys, const std::uint32_t* found, std::uint32_t count,
                                         std::uint32_t* row) {
  constexpr std::uint32_t kFree = ~0u;  // no ball's index
  std::fill(row, row + count, kFree);
  std::uint32_t touching = 0;
  for (std::uint32_t first = 0; first < count; first += 4) {
    const F4 mine = F4::loadu(keys + first);
    simd::I4 smaller = simd::I4::splat(0);
    for (std::uint32_t m = 0; m < count; ++m) smaller = count_where(F4::splat(keys[m]) < mine, smaller);
    alignas(16) std::uint32_t place[4];
    smaller.store(place);
    for (std::uint32_t k = first; k < std::min(first + 4, count); ++k) {
      std::uint32_t at = place[k - first];
      while (row[at] != kFree) ++at;
      row[at] = found[k];
      touching += keys[k] < 0.0f;
    }
  }
  return touching;
}

// A ball's place in its batch: by list length, then by contacts. A group
// costs as many blocks as its longest list, and as many forces as its most
// touching ball's contacts (first in its list); counts past 15 share a key.
inline std::uint8_t length_contacts_key(std::uint32_t touching, std::uint32_t listed) {
  return std::uint8_t(std::min(listed, 15u) * 16 + std::min(touching, 15u));
}

// Balls first..end-1 by their keys (keys[b - first], a counting sort), padded to a multiple of
// `lanes` by repeating the last: it is computed and stored twice, with the same result.
inline std::uint32_t by_length_and_contacts(const std::uint8_t* keys, std::uint32_t first, std::uint32_t end,
                                            std::uint32_t lanes, std::uint32_t* order) {
  constexpr std::uint32_t kBuckets = 256;
  std::uint32_t start[kBuckets + 1] = {};
  for (std::uint32_t b = first; b < end; ++b) ++start[keys[b - first] + 1];
  for (std::uint32_t c = 1; c <= kBuckets; ++c) start[c] += start[c - 1];
  for (std::uint32_t b = first; b < end; ++b) order[start[keys[b - first]]++] = b;
  std::uint32_t n = end - first;
  for (; n % lanes != 0; ++n) order[n] = order[n - 1];
  return n;
}

// Rows within kNearRows of a batch are in reach of that prefetch or were read
// lately; rows further away (across a column block's faces) are remote.
constexpr std::uint32_t kNearRows = 16 * kStepBatch;

inline bool is_remote_row(std::uint32_t row, std::uint32_t batch) {
  return row + kNearRows < batch || row >= batch + kStepBatch + kNearRows;
}

// The remote rows named by the lists of balls batch..last - 1 (stored at
// rows, b.stride apart). A batch whose reach names none, as in the product's
// tank, is not searched entry by entry.
inline RemoteRows remote_rows_of(const ListBuild& b, const std::uint32_t* rows, std::uint32_t batch, std::uint32_t last,
                                 BatchReach reach) {
  RemoteRows remote;
  if (reach.lowest > reach.highest || (!is_remote_row(reach.lowest, batch) && !is_remote_row(reach.highest, batch)))
    return remote;
  for (std::uint32_t i = batch; i < last; ++i) {
    const std::uint32_t* const row = rows + std::size_t(i - batch) * b.stride;
    const std::uint32_t stored = std::min(b.counts[i], b.stride);
    for (std::uint32_t k = 0; k < stored; ++k)
      if (is_remote_row(row[k], batch)) remote.add(row[k]);
  }
  return remote;
}

// The lists of balls [begin, end) for groups of kLanes (broadphase.h): each
// batch's lists found into cached scratch rows, the batch ordered by length
// and contacts, and each group's rows interleaved into blocks.
template <std::uint32_t kLanes>
std::uint32_t build_lists(const ListBuild& b, std::uint32_t begin, std::uint32_t end) {
  thread_local std::vector<std::uint32_t> rows, found;
  thread_local std::vector<float> keys;
  rows.resize(std::size_t(kStepBatch) * b.stride);
  found.resize(b.stride);
  keys.resize(b.stride + 3);
  std::uint32_t longest = 0;
  for (std::uint32_t batch = begin, last_of_batch; batch < end; batch = last_of_batch) {
    last_of_batch = batch_end(batch, end);
    BatchReach reach;  // a local: stores to the lists cannot change it
    std::uint8_t group_keys[kStepBatch];
    for (std::uint32_t i = batch; i < last_of_batch; ++i) {
      std::uint32_t* const row = rows.data() + std::size_t(i - batch) * b.stride;
      b.counts[i] = list_of(b, i, found.data(), keys.data());
      longest = std::max(longest, b.counts[i]);
      const std::uint32_t stored = std::min(b.counts[i], b.stride);
      group_keys[i - batch] = length_contacts_key(order_nearest_first(keys.data(), found.data(), stored, row), stored);
      for (std::uint32_t k = 0; k < stored; ++k) reach.add(row[k]);
    }
    b.reach[batch / kStepBatch] = reach;
    if (b.remote_rows) b.remote_rows[batch / kStepBatch] = remote_rows_of(b, rows.data(), batch, last_of_batch, reach);
    std::uint32_t* order = b.batch_order + batch;
    const std::uint32_t grouped = by_length_and_contacts(group_keys, batch, last_of_batch, kLanes, order);
    std::uint32_t* block = b.neighbours + std::size_t(batch) * b.stride;
    for (const std::uint32_t* group = order; group < order + grouped; group += kLanes) {
      const std::uint32_t* row[kLanes];
      std::uint32_t count[kLanes], blocks = 0;
      for (std::uint32_t l = 0; l < kLanes; ++l) {
        row[l] = rows.data() + std::size_t(group[l] - batch) * b.stride;
        count[l] = std::min(b.counts[group[l]], b.stride);
        blocks = std::max(blocks, count[l]);
      }
      for (std::uint32_t n = 0; n < blocks; ++n, block += kLanes)
        for (std::uint32_t l = 0; l < kLanes; ++l) block[l] = list_entry(n < count[l] ? row[l][n] : b.n);
      const std::size_t place = group - b.batch_order;
      write_group_record(b.pos, group, kLanes, b.group_records + 4 * place);
      b.group_blocks[place / kLanes] = blocks;
    }
  }
  return longest;
}

}  // namespace
}  // namespace fishtank
