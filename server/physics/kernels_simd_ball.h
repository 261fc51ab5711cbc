#pragma once
// What the two SIMD kernel files share: the step and acceleration passes,
// written once for a vector type V, and the neighbour-list build.
//
// A vector carries a group of balls, one per lane: four in F4
// (kernels_sse.cpp), eight in F8 (kernels_avx2.cpp); each file says how to
// gather and scatter its lanes (Lanes<V>). For its neighbour sums each lane
// walks its own ball's list, one neighbour per block, so a group costs as
// many blocks as its longest list: the list build orders each list nearest
// first (order_nearest_first), forms groups of balls with similar list
// lengths and then counts of contacts (by_length_and_contacts) and lays
// their lists out block by block (build_lists, and broadphase.h for the
// layout); the step skips the force of blocks in which no lane touches. Walls,
// player spheres, kick and drift then serve the whole group per instruction
// too.
//
// Both files include this header and are compiled with different -m flags, so
// everything here has internal linkage: each gets its own copy in its own
// instruction set, and the linker can never hand AVX2 code to the SSE build.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/simd/sse_float4.h"
#include "server/physics/kernels.h"

namespace fishtank {
namespace {

using simd::F4;
using simd::M4;

// Set bits of a 4-bit mask (the SSE4.1 build has no popcnt instruction:
// __builtin_popcount would be a library call).
constexpr std::uint8_t kSetBits[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};

// Ball i's list as found into found (at most b.stride entries), and beside
// each entry its key d^2 - (r_i + r_j)^2 (order_nearest_first); returns the
// true count. Four candidates at a time: a cell range is contiguous in the
// sorted arrays, so four consecutive balls are tested at once, with one load
// per axis from ListBuild's axis arrays, and the indices and keys of those
// within reach are packed into found and keys with one byte shuffle each,
// with no branch per candidate (the scalar build mispredicts on most of them).
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

// Ball i's count entries, as found with their keys, into row nearest first
// (see kernels_scalar.cpp's twin for the order); returns how many touch.
// Each entry's place is the number of entries with a smaller key, found for
// four entries per instruction; entries with equal keys then take the next
// free places in the order found. Lists are short (7.5 entries in the
// settled tank) and the only branch, on a place being taken, almost never
// goes the other way. keys is read up to three entries past count.
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

// A ball's place in the order of its batch: by the length of its list, then
// by how many of the balls on it touch it. A group costs as many blocks as
// its longest list, and as many with a force to compute as its most touching
// ball's contacts (order_nearest_first puts them first). Grouping by length
// keeps the blocks full, so the lists take no more memory than they need
// (the step of a million balls waits on memory, not on arithmetic), and
// within a length by contacts keeps the blocks with a force few. Counts past
// 15 share a key: only the grouping is coarser.
inline std::uint8_t length_contacts_key(std::uint32_t touching, std::uint32_t listed) {
  return std::uint8_t(std::min(listed, 15u) * 16 + std::min(touching, 15u));
}

// Balls first..end-1 of a batch by their length_contacts_key (a counting sort;
// keys[b - first] is ball b's), padded to a multiple of `lanes` with the
// last one repeated: a repeated ball is computed twice and stored twice,
// with the same result. Returns the length.
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

// Beyond the caches (the wide scene from 100 000 balls) a batch's rows arrive
// late if left to the hardware, which sees them gathered and scattered in the
// order of the groups, not of the addresses. So each group asks for its share
// of the rows and lists of the batch kPrefetchBatches ahead: share is the
// group's place in its batch. At 1 000 000 balls asking one batch ahead took
// the step pass from 28.7 to 23.7 ns per ball-step, and four ahead (~60 KB of
// rows and lists, a few microseconds of work) from 16.0-19.2 to 11.3-12.1
// against one: one batch's ~2 us did not cover the memory's latency under two
// threads' misses. From cache it changes nothing measurable, and it costs 3 %
// more instructions, so the world asks for it only for piles larger than the
// caches (StepArrays::beyond_cache; technical report, 6.2).
constexpr std::uint32_t kPrefetchBatches = 4;

// A batch's lists name rows close to it in the sorted order (its own cells
// and the rows and layers of cells around them), except across a column
// block's x faces (broadphase.h), where the neighbours lie a whole block of
// balls away and neither the rows asked for ahead nor those read lately hold
// them. In the wide scene's million 6.9 % of the balls name such rows,
// 60 000 balls away, 0.09 cache lines per ball, and they cost one thread's
// step pass 23.5-25.9 ns per ball-step against 19.5-20.4 with them asked for
// (12.3 for a stretch of 10 240 of its balls stepped over and over in the
// caches; technical report, 6.2). So the build notes the rows more than
// kNearRows from a batch (FarRows), and the step asks for them with the
// batch's own rows. Nearer rows are left out: behind, the step read them
// lately and they are still in the second-level cache (~290 KB at the ~140
// bytes a ball-step moves, of 1 MB); ahead, they are the next layers of
// cells, within the batch-ahead prefetch's reach in the wide scene (the
// million's lists name rows at most 294 balls ahead within a block, 99th
// percentile).
constexpr std::uint32_t kNearRows = 16 * kStepBatch;

inline bool is_far_row(std::uint32_t row, std::uint32_t batch) {
  return row + kNearRows < batch || row >= batch + kStepBatch + kNearRows;
}

// The far rows of the lists of balls batch..last - 1, stored at rows
// (b.stride apart). reach says what they name, so a batch whose lists name
// no far row, as in the product's tank, is not searched: testing every entry
// as the lists were found made the tank's build 10-25 % slower (technical
// report, section 3).
inline FarRows far_rows_of(const ListBuild& b, const std::uint32_t* rows, std::uint32_t batch, std::uint32_t last,
                           BatchReach reach) {
  FarRows far;
  if (reach.lowest > reach.highest || (!is_far_row(reach.lowest, batch) && !is_far_row(reach.highest, batch)))
    return far;
  for (std::uint32_t i = batch; i < last; ++i) {
    const std::uint32_t* const row = rows + std::size_t(i - batch) * b.stride;
    const std::uint32_t stored = std::min(b.counts[i], b.stride);
    for (std::uint32_t k = 0; k < stored; ++k)
      if (is_far_row(row[k], batch)) far.add(row[k]);
  }
  return far;
}

// The lists of balls [begin, end), laid out for groups of kLanes balls
// (broadphase.h): each batch's lists are found into rows of a scratch buffer
// that stays in the cache and ordered nearest first, the batch is ordered by
// list length and contacts, and each group's rows are interleaved into
// blocks, the ghost where a list has ended. The step then reads one
// contiguous block per vector of neighbours, and the lists take as much
// memory as the groups need, not a stride per ball.
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
    if (b.far_rows) b.far_rows[batch / kStepBatch] = far_rows_of(b, rows.data(), batch, last_of_batch, reach);
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

// Lanes<V> (each kernel file) says how a vector holds a group of balls, one
// per lane: kCount lanes; load(rows, at, x, y, z, w) gathers the rows at list
// entries at[0..] (byte offsets, broadphase.h) into lanes; store(x, y, z, w,
// rows, at) scatters them back; largest(a) is the largest lane.
template <class V>
struct Lanes;

// A group's balls, one per lane.
template <class V>
struct GroupBalls {
  V x, y, z, r;  // position, radius
  V vx, vy, vz;  // half-step velocity
  V inv_m;       // 1 / mass
};

// Sum over each lane's neighbours of the spring-dashpot force, into fx, fy, fz.
// Each lane walks its own ball's list, one neighbour per block, and adds in list
// order, as the scalar twin does. d and dv point from ball i to its neighbour,
// the opposite of the scalar twin's, so SSE's two-operand subtract works in
// place on the gathered neighbour lanes with no copies; the negations are exact
// and cancel in pairs, so every value is the scalar formula's (up to the
// estimates).
template <class V>
[[gnu::always_inline]] inline void neighbour_forces(const StepArrays& s, const ContactModel& m,
                                                    const std::uint32_t* block, std::uint32_t blocks,
                                                    const GroupBalls<V>& i, V& fx, V& fy, V& fz) {
  const V k = V::splat(m.k), damping = V::splat(m.damping_factor);
  const V tiny = V::splat(1e-12f);  // squared distance floor: coincident centres stay finite
  fx = fy = fz = V::zero();
  // Past its end, a shorter list's lane holds the ghost: it touches nothing.
  for (const std::uint32_t* const last = block + blocks * Lanes<V>::kCount; block < last; block += Lanes<V>::kCount) {
    V dx, dy, dz, rj;
    Lanes<V>::load(s.pos, block, dx, dy, dz, rj);
    dx -= i.x, dy -= i.y, dz -= i.z;
    const V d2 = mul_add(dz, dz, mul_add(dy, dy, dx * dx));
    const V reach = rj + i.r;
    const auto touching = d2 < reach * reach;
    // The lists are ordered nearest first at the build, and groups formed by
    // length and then contacts: the last blocks of a group usually hold only
    // pairs that the skin keeps, with no force to compute.
    if (!simd::any(touching)) continue;
    V dvx, dvy, dvz, inv_mj;
    Lanes<V>::load(s.vel_half, block, dvx, dvy, dvz, inv_mj);
    dvx -= i.vx, dvy -= i.vy, dvz -= i.vz;
    const V neg_inv_dist = simd::neg_rsqrt(max(d2, tiny));
    const V neg_dist = d2 * neg_inv_dist;
    const V v_n_dist = mul_add(dvz, dz, mul_add(dvy, dy, dvx * dx));  // v_n |d|
    // sqrt(m_eff) = 1 / sqrt(1/mi + 1/mj): the rows carry inverse masses. A square root and a
    // divide, exactly the scalar twin's value: the divider is otherwise idle in this loop, and the
    // estimate with its Newton step took more instructions (technical report, section 4).
    const V c = damping / sqrt(i.inv_m + inv_mj);  // damping * sqrt(m_eff)
    // f / |d| multiplies the unnormalised d: the normal is never formed.
    const V f_over_dist = keep(touching, mul_add(c, v_n_dist * neg_inv_dist, k * (reach + neg_dist)) * neg_inv_dist);
    fx = mul_add(f_over_dist, dx, fx);
    fy = mul_add(f_over_dist, dy, fy);
    fz = mul_add(f_over_dist, dz, fz);
  }
}

// One axis of the six half-space walls: below the minimum face the force
// points +axis, above the maximum face -axis; both grow with depth.
template <class V>
[[gnu::always_inline]] inline V wall_force(V k, V c, V p, V v, V r, float lo, float hi) {
  const V below = V::splat(lo) + r - p;
  const V above = p + r - V::splat(hi);
  return keep(below > V::zero(), k * below - c * v) - keep(above > V::zero(), k * above + c * v);
}

// a = F / m + g for a group's balls: their neighbours' forces f, plus walls
// and player spheres.
template <class V>
[[gnu::always_inline]] inline void acceleration(const StepArrays& s, const ContactModel& m, const GroupBalls<V>& i,
                                                V& fx, V& fy, V& fz) {
  const TankBounds& t = m.tank;
  const V r = i.r;
  const auto in_wall = (V::splat(t.min.x) + r > i.x) | (i.x + r > V::splat(t.max.x)) | (V::splat(t.min.y) + r > i.y) |
                       (i.y + r > V::splat(t.max.y)) | (V::splat(t.min.z) + r > i.z) | (i.z + r > V::splat(t.max.z));
  if (simd::any(in_wall) || s.players > 0) {  // most groups touch no wall
    const V k = V::splat(m.k);
    const V c = V::splat(m.damping_factor) / sqrt(i.inv_m);  // walls and players are kinematic: m_eff = m
    fx += wall_force(k, c, i.x, i.vx, r, t.min.x, t.max.x);
    fy += wall_force(k, c, i.y, i.vy, r, t.min.y, t.max.y);
    fz += wall_force(k, c, i.z, i.vz, r, t.min.z, t.max.z);
    for (int p = 0; p < s.players; ++p) {
      const Float4 pp = s.player_pos[p], pv = s.player_vel[p];
      const V dx = i.x - V::splat(pp.x), dy = i.y - V::splat(pp.y), dz = i.z - V::splat(pp.z);
      const V d2 = mul_add(dz, dz, mul_add(dy, dy, dx * dx));
      const V reach = r + V::splat(pp.w);
      const auto touching = d2 < reach * reach;
      if (!simd::any(touching)) continue;
      const V dist = max(sqrt(d2), V::splat(1e-6f));
      const V inv_dist = V::splat(1.0f) / dist;
      const V v_n =
          ((i.vx - V::splat(pv.x)) * dx + (i.vy - V::splat(pv.y)) * dy + (i.vz - V::splat(pv.z)) * dz) * inv_dist;
      const V f_over_dist = keep(touching, (k * (reach - dist) - c * v_n) * inv_dist);
      fx = mul_add(f_over_dist, dx, fx);
      fy = mul_add(f_over_dist, dy, fy);
      fz = mul_add(f_over_dist, dz, fz);
    }
  }
  fx = fx * i.inv_m;
  fy = fy * i.inv_m - V::splat(m.gravity);
  fz = fz * i.inv_m;
}

constexpr std::size_t kCacheLine = 64;

// How a line asked for ahead will be used: read again by later groups (a
// batch's rows are the neighbours of the batches around it), or touched once
// this step (the groups' records and lists, read once; the next-step rows,
// written once). Lines of the second kind are asked for non-temporally
// (prefetchnta), so that they do not push the rows read again out of the
// caches: on the million balls of the wide scene, alternating with asking
// for every line alike window by window in one process, the step pass took
// 11.4-12.0 ns per ball-step against 12.1-13.2 (eight windows each), and
// 100 000 balls 9.7-10.1 against 9.9-10.3; asking for the rows
// non-temporally too was no better (technical report, 6.2).
enum class Reuse { kAgain, kOnce };

// Asks for the cache line `bytes` past `base`. A prefetch never faults, so
// the address may lie past an array's end; it is formed as an integer, not
// by pointer arithmetic.
template <Reuse kReuse>
inline void prefetch(const void* base, std::size_t bytes) {
  constexpr int kLocality = kReuse == Reuse::kAgain ? 3 : 0;  // 0: prefetchnta
  __builtin_prefetch(reinterpret_cast<const void*>(reinterpret_cast<std::uintptr_t>(base) + bytes), 0, kLocality);
}

template <std::uint32_t kCount>
[[gnu::always_inline]] inline void prefetch_batch_ahead(const StepArrays& s, std::uint32_t batch, std::uint32_t share) {
  const std::size_t ahead = std::size_t(batch) + kPrefetchBatches * kStepBatch;
  const std::size_t rows = (ahead + share * kCount) * sizeof(Float4);
  for (std::size_t line = rows; line < rows + kCount * sizeof(Float4); line += kCacheLine) {
    prefetch<Reuse::kAgain>(s.pos, line);
    prefetch<Reuse::kAgain>(s.vel_half, line);
    prefetch<Reuse::kOnce>(s.group_records, line);  // 16 bytes per ball too, in the batch's group order
    prefetch<Reuse::kOnce>(s.pos_next, line);
    prefetch<Reuse::kOnce>(s.vel_half_next, line);
  }
  // A group's blocks take about eight entries (32 bytes) per lane.
  const std::size_t lists = ahead * s.stride * sizeof(std::uint32_t);
  for (std::size_t line = share * kCount * 32; line < (share + 1) * kCount * 32; line += kCacheLine)
    prefetch<Reuse::kOnce>(s.neighbours, lists + line);
  // And the batch's far rows, a few per group.
  const std::size_t far_batch = ahead / kStepBatch;
  if (far_batch >= s.batches) return;
  const FarRows& far = s.far_rows[far_batch];
  for (std::uint32_t k = share; k < far.count; k += kStepBatch / kCount) {
    prefetch<Reuse::kAgain>(s.pos, std::size_t(far.rows[k]) * sizeof(Float4));
    prefetch<Reuse::kAgain>(s.vel_half, std::size_t(far.rows[k]) * sizeof(Float4));
  }
}

inline bool in_window(const RowFetch& f, std::uint32_t batch) { return batch >= f.first_batch && batch < f.end_batch; }

// Asks for this group's share of a RowFetch's cache lines, when `batch` (a
// batch number) is in its window; `share` is the group's place in its batch.
template <std::uint32_t kCount>
[[gnu::always_inline]] inline void fetch_rows(const StepArrays& s, const RowFetch& f, std::uint32_t batch,
                                              std::uint32_t share) {
  if (!in_window(f, batch)) return;
  constexpr std::size_t kGroups = kStepBatch / kCount;
  const std::size_t first_line = f.rows_begin * sizeof(Float4) / kCacheLine;
  const std::size_t end_line = (f.rows_end * sizeof(Float4) + kCacheLine - 1) / kCacheLine;
  const std::size_t groups = (f.end_batch - f.first_batch) * kGroups;
  const std::size_t per_group = (end_line - first_line + groups - 1) / groups;
  const std::size_t from = first_line + ((batch - f.first_batch) * kGroups + share) * per_group;
  for (std::size_t line = from; line < std::min(end_line, from + per_group); ++line) {
    prefetch<Reuse::kAgain>(s.pos, line * kCacheLine);
    prefetch<Reuse::kAgain>(s.vel_half, line * kCacheLine);
  }
}

// Each pass takes a batch's groups (kStepBatch, broadphase.h), one ball per
// lane: the neighbour sums from the group's blocks, walls and players give
// a = F / m + g for the group's balls at once, and per_group(at, i, ax, ay,
// az, record) does the rest (the step: kick and drift) and scatters the
// results back to their rows at list entries `at`; record is the group's
// (broadphase.h). A padded group repeats a ball: it is computed twice and
// stored twice, with the same result.
template <class V, class PerGroup>
[[gnu::always_inline]] inline void for_each_group_of_batch(const StepArrays& s, const ContactModel& m,
                                                           std::uint32_t batch, std::uint32_t end,
                                                           PerGroup& per_group) {
  constexpr std::uint32_t kCount = Lanes<V>::kCount;
  const std::uint32_t* block = s.neighbours + std::size_t(batch) * s.stride;
  const std::uint32_t groups = grouped_length(batch_end(batch, end) - batch, kCount) / kCount;
  const std::uint32_t* const group_blocks = s.group_blocks + batch / kCount;
  const std::uint32_t* record = s.group_records + 4 * std::size_t(batch);
  // Decided once per batch: most batches are in no fetch's window (all, on one thread).
  const std::uint32_t batch_number = batch / kStepBatch;
  const bool fetching = in_window(s.edge_fetch[0], batch_number) || in_window(s.edge_fetch[1], batch_number);
  for (std::uint32_t share = 0; share < groups; ++share, record += 4 * kCount) {
    if (s.beyond_cache) prefetch_batch_ahead<kCount>(s, batch, share);
    if (fetching)
      for (const RowFetch& f : s.edge_fetch) fetch_rows<kCount>(s, f, batch_number, share);
    const std::uint32_t blocks = group_blocks[share];
    const std::uint32_t* const at = record + 3 * kCount;  // the group's list entries
    GroupBalls<V> i;
    Lanes<V>::load(s.pos, at, i.x, i.y, i.z, i.r);
    Lanes<V>::load(s.vel_half, at, i.vx, i.vy, i.vz, i.inv_m);
    V ax, ay, az;
    neighbour_forces(s, m, block, blocks, i, ax, ay, az);
    acceleration(s, m, i, ax, ay, az);
    per_group(at, i, ax, ay, az, record);
    block += std::size_t(blocks) * kCount;
  }
}

// The chunk's lead batches first (StepArrays::lead_begin), then the others in order.
template <class V, class PerGroup>
[[gnu::always_inline]] inline void for_each_group(const StepArrays& s, const ContactModel& m, std::uint32_t begin,
                                                  std::uint32_t end, PerGroup per_group) {
  const bool led = s.lead_begin < s.lead_end;
  const std::uint32_t lead_begin = led ? s.lead_begin : begin, lead_end = led ? s.lead_end : begin;
  const std::uint32_t from[3] = {lead_begin, begin, lead_end}, to[3] = {lead_end, lead_begin, end};
  for (int part = 0; part < 3; ++part)
    for (std::uint32_t batch = from[part]; batch < to[part]; batch += kStepBatch)
      for_each_group_of_batch<V>(s, m, batch, end, per_group);
}

template <class V>
Moved step(const StepArrays& arrays, const ContactModel& model, std::uint32_t begin, std::uint32_t end) {
  // Local copies: stores through the output pointers cannot change them, so
  // pointers and constants stay in registers instead of being reloaded.
  const StepArrays s = arrays;
  const ContactModel m = model;
  V max_d2 = V::zero();
  const V far_d2 = V::splat(s.far_d2);
  std::uint32_t* const far_balls = s.far_balls + begin;
  std::uint32_t far = 0;
  for_each_group<V>(
      s, m, begin, end,
      [&](const std::uint32_t* at, const GroupBalls<V>& i, V ax, V ay, V az, const std::uint32_t* record) {
        const V half_dt = V::splat(m.half_dt), dt = V::splat(m.dt);
        const V vx = mul_add(ax, half_dt, i.vx), vy = mul_add(ay, half_dt, i.vy), vz = mul_add(az, half_dt, i.vz);
        const V hx = mul_add(ax, half_dt, vx), hy = mul_add(ay, half_dt, vy), hz = mul_add(az, half_dt, vz);
        Lanes<V>::store(hx, hy, hz, i.inv_m, s.vel_half_next, at);
        const V px = mul_add(hx, dt, i.x), py = mul_add(hy, dt, i.y), pz = mul_add(hz, dt, i.z);
        Lanes<V>::store(px, py, pz, i.r, s.pos_next, at);
        // Where the lanes' balls were at the build: the record's first three vectors.
        constexpr std::uint32_t kCount = Lanes<V>::kCount;
        V bx = V::load_bits(record), by = V::load_bits(record + kCount), bz = V::load_bits(record + 2 * kCount);
        bx -= px, by -= py, bz -= pz;
        const V d2 = mul_add(bz, bz, mul_add(by, by, bx * bx));
        max_d2 = max(max_d2, d2);
        if (int lanes = simd::bits(d2 > far_d2)) [[unlikely]] {
          // A padded group repeats its last ball in the lanes after it: list it once.
          for (std::uint32_t l = 0; l < Lanes<V>::kCount; ++l, lanes >>= 1)
            if ((lanes & 1) && (l == 0 || at[l] != at[l - 1])) far_balls[far++] = listed_index(at[l]);
        }
      });
  return Moved{Lanes<V>::largest(max_d2), far};
}

template <class V>
void accelerations(const StepArrays& s, const ContactModel& m, Float4* acc, std::uint32_t begin, std::uint32_t end) {
  for_each_group<V>(s, m, begin, end,
                    [&](const std::uint32_t* at, const GroupBalls<V>&, V ax, V ay, V az, const std::uint32_t*) {
                      Lanes<V>::store(ax, ay, az, V::zero(), acc, at);
                    });
}

}  // namespace
}  // namespace fishtank
