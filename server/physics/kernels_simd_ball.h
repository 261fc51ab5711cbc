#pragma once
// What the two SIMD kernel files share, written once for a vector type V:
// the step and acceleration passes and the neighbour-list build. A vector
// carries a group of balls, one per lane (four in F4, eight in F8), and each
// lane walks its own ball's list, one neighbour per block; each kernel file
// says how to gather and scatter its lanes (Lanes<V>). Both files compile this
// with different -m flags, so everything here has internal linkage: the linker
// can never hand AVX2 code to the SSE build.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/simd/sse_float4.h"
#include "server/physics/contact_law.h"
#include "server/physics/kernels.h"
#include "server/physics/prefetch_plan.h"

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

// Beyond the caches, rows gathered in group order arrive late if left to the
// hardware's prefetcher, so each group asks for its share of the rows and
// lists kPrefetchBatches ahead, enough batches to cover memory latency.
constexpr std::uint32_t kPrefetchBatches = 4;

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

// Lanes<V> (each kernel file): kCount lanes; load gathers the rows list entries at[0..] name into
// lanes, store scatters them back, largest(a) is the largest lane.
template <class V>
struct Lanes;

// c and whole_window_damping (contact_law.h) of each pair of ball kinds,
// and of each kind against a wall or a player (kinematic: m_eff = m). Made
// once per batch with the scalar law, the same values each lane would compute:
// a group then picks its lanes' rows instead of taking square roots and quotients.
struct KindDamping {
  struct Dashpot {
    float c, now, before;
  };
  Dashpot pair[kKindCount][kKindCount];  // [kind of i][kind of j]
  Dashpot kinematic[kKindCount];

  static Dashpot dashpot(const ContactModel& m, float inv_m_sum) {
    const float c = contact_damping(m, inv_m_sum);
    const WholeWindowDamping d = whole_window_damping(m, c, inv_m_sum);
    return {c, d.now, d.before};
  }

  explicit KindDamping(const ContactModel& m) {
    for (int a = 0; a < kKindCount; ++a) {
      const float inv_m = 1.0f / kBallKinds[a].mass;
      kinematic[a] = dashpot(m, inv_m);
      for (int b = 0; b < kKindCount; ++b) pair[a][b] = dashpot(m, inv_m + 1.0f / kBallKinds[b].mass);
    }
  }
};

// Each lane's dashpot of_kind[its kind]; a ball's kind is known by its 1 / mass.
template <class V>
[[gnu::always_inline]] inline WholeDashpot<V> of_kinds(V inv_m, const WholeDashpot<V> (&of_kind)[kKindCount]) {
  WholeDashpot<V> d = of_kind[0];
  for (int k = 1; k < kKindCount; ++k) {
    const auto lanes = inv_m == V::splat(1.0f / kBallKinds[k].mass);
    d = {select(lanes, of_kind[k].c, d.c), select(lanes, of_kind[k].now, d.now),
         select(lanes, of_kind[k].before, d.before)};
  }
  return d;
}

// Each lane's dashpot from a per-kind row of the table.
template <class V>
[[gnu::always_inline]] inline WholeDashpot<V> of_lane_kinds(V inv_m,
                                                            const KindDamping::Dashpot (&of_kind)[kKindCount]) {
  WholeDashpot<V> rows[kKindCount];
  for (int k = 0; k < kKindCount; ++k)
    rows[k] = {V::splat(of_kind[k].c), V::splat(of_kind[k].now), V::splat(of_kind[k].before)};
  return of_kinds(inv_m, rows);
}

// A group's balls, one per lane.
template <class V>
struct GroupBalls {
  V x, y, z, r;  // position, radius
  V vx, vy, vz;  // half-step velocity
  V inv_m;       // 1 / mass
  V bx, by, bz;  // half-step velocity a step earlier (StepArrays::vel_half_before)
  const KindDamping* kinds;
  const std::uint32_t* at;  // their list entries
};

// Below this lead bound (every ball nearly at rest), lanes that need the whole law are rare: a branch per block
// lists them, and each group sums them after its other blocks (neighbour_forces); in a moving pile they are
// common, listed without a branch, and summed once the batch's other blocks are.
constexpr float kStillLead = 1e-3f;

// A block of a group's lists in which some lane needs the whole law (needs_whole_law).
struct WholeLawBlock {
  const std::uint32_t* block;
  std::uint32_t share;  // the group's place in its batch
};

// Where a block's neighbours are and how they move, seen from the group's balls.
template <class V>
struct BlockPairs {
  V dx, dy, dz;  // from ball i to its neighbour
  V inv_dist, overlap, v_n;
  V inv_mj;  // the neighbour's 1 / mass
};

template <class V>
[[gnu::always_inline]] inline BlockPairs<V> block_pairs(const StepArrays& s, const std::uint32_t* block,
                                                        const GroupBalls<V>& i, V dx, V dy, V dz, V d2, V reach) {
  const V tiny = V::splat(1e-12f);  // squared distance floor: coincident centres stay finite
  V dvx, dvy, dvz, inv_mj;
  Lanes<V>::load(s.vel_half, block, dvx, dvy, dvz, inv_mj);
  dvx -= i.vx, dvy -= i.vy, dvz -= i.vz;
  const V inv_dist = simd::rsqrt(max(d2, tiny));
  return {dx, dy, dz, inv_dist, reach - d2 * inv_dist, mul_add(dvz, dz, mul_add(dvy, dy, dvx * dx)) * inv_dist, inv_mj};
}

// Each lane's pair's rate a step earlier, along today's normal.
template <class V>
[[gnu::always_inline]] inline V pair_rate_before(const StepArrays& s, const std::uint32_t* block,
                                                 const GroupBalls<V>& i, const BlockPairs<V>& p) {
  V bx, by, bz, unused;
  Lanes<V>::load(s.vel_half_before, block, bx, by, bz, unused);
  return mul_add(bz - i.bz, p.dz, mul_add(by - i.by, p.dy, (bx - i.bx) * p.dx)) * p.inv_dist;
}

// c of each lane's pair with its neighbour of 1 / mass inv_mj.
template <class V>
[[gnu::always_inline]] inline V pair_c(const GroupBalls<V>& i, V inv_mj) {
  V c = V::zero();
  for (int k = 0; k < kKindCount; ++k)  // the tables are symmetric
    c = select(inv_mj == V::splat(1.0f / kBallKinds[k].mass), of_lane_kinds(i.inv_m, i.kinds->pair[k]).c, c);
  return c;
}

// Adds a force of magnitude f_over_dist · |d| along -d, pushing each lane's ball away from what it touches.
template <class V>
[[gnu::always_inline]] inline void push_apart(V f_over_dist, V dx, V dy, V dz, V& fx, V& fy, V& fz) {
  fx = neg_mul_add(f_over_dist, dx, fx);
  fy = neg_mul_add(f_over_dist, dy, fy);
  fz = neg_mul_add(f_over_dist, dz, fz);
}

// Sum over each lane's neighbours of the contact force, into fx, fy, fz, in
// list order as in the scalar twin (deferred lanes after the rest). Most
// contacts last the whole step (or are none): their law is whole_or_no_contact_force,
// with the dashpot taken by the neighbour's kind from a table made once per group.
// A lane whose contact starts or ends, now or a step before, takes the whole law (contact_law.h)
// later, in whole_law_forces, its block listed at `deferred`, so that this loop
// stays short. Where a pile moves such blocks are common and a branch per block
// would be mispredicted often, so they are listed without one (kBranchFree); at
// rest they are rare, and a branch skips the listing.
template <bool kBranchFree, class V>
[[gnu::always_inline]] inline void neighbour_forces(const StepContext& ctx, const std::uint32_t* block,
                                                    std::uint32_t blocks, const GroupBalls<V>& i, V& fx, V& fy, V& fz,
                                                    std::uint32_t share, WholeLawBlock*& deferred) {
  const StepArrays& s = ctx.arrays;
  const ContactModel& m = ctx.model;
  // A neighbour's kind is known by its 1 / mass: the dashpot of each lane's pair with each kind.
  WholeDashpot<V> kind_dashpot[kKindCount];
  for (int k = 0; k < kKindCount; ++k) kind_dashpot[k] = of_lane_kinds(i.inv_m, i.kinds->pair[k]);
  const V lead_bound = V::splat(m.lead_bound);
  fx = fy = fz = V::zero();
  // Past its end, a shorter list's lane holds the ghost: it touches nothing.
  for (const std::uint32_t* const last = block + blocks * Lanes<V>::kCount; block < last; block += Lanes<V>::kCount) {
    V dx, dy, dz, rj;
    Lanes<V>::load(s.pos, block, dx, dy, dz, rj);
    dx -= i.x, dy -= i.y, dz -= i.z;
    const V d2 = mul_add(dz, dz, mul_add(dy, dy, dx * dx));
    const V reach = rj + i.r, reach_lead = reach + lead_bound;
    const auto near = d2 < reach_lead * reach_lead;
    // Lists are ordered nearest first: a group's last blocks mostly hold pairs only the skin keeps.
    if (!simd::any(near)) continue;
    const BlockPairs<V> p = block_pairs(s, block, i, dx, dy, dz, d2, reach);
    // Lanes that are not near cannot start within the step (lead_bound bounds every lead).
    const V v_before = pair_rate_before(s, block, i, p);
    const auto whole_law = needs_whole_law(m, p.overlap, p.v_n, v_before);
    V f = whole_or_no_contact_force(m, p.overlap, p.v_n, v_before, of_kinds(p.inv_mj, kind_dashpot));
    if constexpr (kBranchFree) {  // those lanes' force comes from whole_law_forces
      f = select(whole_law, V::zero(), f);
      *deferred = {block, share};
      deferred += simd::any(whole_law);
    } else if (simd::any(whole_law)) [[unlikely]] {
      f = select(whole_law, V::zero(), f);
      *deferred++ = {block, share};
    }
    push_apart(f * p.inv_dist, dx, dy, dz, fx, fy, fz);
  }
}

// The whole law's force on the lanes of one deferred block that need it, added to f.
template <class V>
[[gnu::always_inline]] inline void whole_law_forces(const StepContext& ctx, const std::uint32_t* block,
                                                    const GroupBalls<V>& i, V (&f)[3]) {
  const StepArrays& s = ctx.arrays;
  const ContactModel& m = ctx.model;
  V dx, dy, dz, rj;
  Lanes<V>::load(s.pos, block, dx, dy, dz, rj);
  dx -= i.x, dy -= i.y, dz -= i.z;
  const V d2 = mul_add(dz, dz, mul_add(dy, dy, dx * dx));
  const V reach = rj + i.r, reach_lead = reach + V::splat(m.lead_bound);
  const BlockPairs<V> p = block_pairs(s, block, i, dx, dy, dz, d2, reach);
  const V v_before = pair_rate_before(s, block, i, p);
  const auto lanes = (d2 < reach_lead * reach_lead) & needs_whole_law(m, p.overlap, p.v_n, v_before);
  const V f_over_dist =
      keep(lanes, normal_force(m, p.overlap, p.v_n, pair_c(i, p.inv_mj), i.inv_m + p.inv_mj, v_before)) * p.inv_dist;
  push_apart(f_over_dist, dx, dy, dz, f[0], f[1], f[2]);
}

// One axis of the six half-space walls: below the minimum face the force
// points +axis, above the maximum face -axis; both grow with depth. A ball
// reaches one face of an axis at most, so the law runs once, on the nearer
// face (the other's force is zero); where no lane needs the whole law
// there, it is whole_or_no_contact_force with the group's dashpot d (contact_law.h).
// before: the lanes' velocity along the axis a step earlier.
template <class V>
[[gnu::always_inline]] inline V wall_force(const ContactModel& m, const WholeDashpot<V>& d, V inv_m, V p, V v, V before,
                                           V r, float lo, float hi) {
  const V below = V::splat(lo) + r - p, above = p + r - V::splat(hi);
  const auto lower = below > above;
  const V overlap = select(lower, below, above), v_n = select(lower, v, V::zero() - v);
  const V v_before = select(lower, before, V::zero() - before);
  const V f = simd::any(needs_whole_law(m, overlap, v_n, v_before))
                  ? normal_force(m, overlap, v_n, d.c, inv_m, v_before)
                  : whole_or_no_contact_force(m, overlap, v_n, v_before, d);
  return select(lower, f, V::zero() - f);
}

// a = F / m + g for a group's balls: their neighbours' forces f, plus player
// spheres and walls, added in the scalar twin's order.
template <class V>
[[gnu::always_inline]] inline void acceleration(const StepContext& ctx, const GroupBalls<V>& i, V& fx, V& fy, V& fz) {
  const StepArrays& s = ctx.arrays;
  const ContactModel& m = ctx.model;
  const TankBounds& t = s.tank;
  const V r = i.r, reach = r + V::splat(m.lead_bound);
  const auto near_x = (V::splat(t.min.x) + reach > i.x) | (i.x + reach > V::splat(t.max.x));
  const auto near_y = (V::splat(t.min.y) + reach > i.y) | (i.y + reach > V::splat(t.max.y));
  const auto near_z = (V::splat(t.min.z) + reach > i.z) | (i.z + reach > V::splat(t.max.z));
  const bool walls = simd::any(near_x | near_y | near_z);  // most groups touch no wall
  if (walls || s.players > 0) {
    const WholeDashpot<V> d = of_lane_kinds(i.inv_m, i.kinds->kinematic);
    for (int p = 0; p < s.players; ++p) {
      const Float4 pj = s.player_pos[p], vj = s.player_vel[p];
      const V dx = V::splat(pj.x) - i.x, dy = V::splat(pj.y) - i.y, dz = V::splat(pj.z) - i.z;
      const V d2 = mul_add(dz, dz, mul_add(dy, dy, dx * dx));
      const V reach_lead = r + V::splat(pj.w) + V::splat(m.lead_bound);
      const auto near = d2 < reach_lead * reach_lead;
      if (!simd::any(near)) continue;
      const V dist = max(sqrt(d2), V::splat(1e-6f));
      const V inv_dist = V::splat(1.0f) / dist;
      const V v_n =
          ((V::splat(vj.x) - i.vx) * dx + (V::splat(vj.y) - i.vy) * dy + (V::splat(vj.z) - i.vz) * dz) * inv_dist;
      // The sphere is kinematic, taken as unaccelerated: the pair's rate changed with the ball's velocity.
      const V v_n_before =
          ((V::splat(vj.x) - i.bx) * dx + (V::splat(vj.y) - i.by) * dy + (V::splat(vj.z) - i.bz) * dz) * inv_dist;
      const V f_over_dist =
          keep(near, normal_force(m, r + V::splat(pj.w) - dist, v_n, d.c, i.inv_m, v_n_before) * inv_dist);
      push_apart(f_over_dist, dx, dy, dz, fx, fy, fz);
    }
    if (walls) {  // an axis no lane is near adds zero
      if (simd::any(near_x)) fx += wall_force(m, d, i.inv_m, i.x, i.vx, i.bx, r, t.min.x, t.max.x);
      if (simd::any(near_y)) fy += wall_force(m, d, i.inv_m, i.y, i.vy, i.by, r, t.min.y, t.max.y);
      if (simd::any(near_z)) fz += wall_force(m, d, i.inv_m, i.z, i.vz, i.bz, r, t.min.z, t.max.z);
    }
  }
  fx = fx * i.inv_m;
  fy = fy * i.inv_m - V::splat(m.gravity);
  fz = fz * i.inv_m;
}

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

// A batch's groups, one ball per lane: a = F / m + g, then per_group(at, i, ax, ay, az, record)
// does the rest for the balls at list entries `at`. While the balls move (kStillLead), the blocks
// that need the whole law are summed after all the batch's others, one branch-free pass
// listing them: each group's a waits for that.
template <class V, class PerGroup>
[[gnu::always_inline]] inline void for_each_group_of_batch(const StepContext& ctx, const GroupLists& lists,
                                                           const EdgeFetches& edges, std::uint32_t batch,
                                                           std::uint32_t end, PerGroup& per_group) {
  const StepArrays& s = ctx.arrays;
  const ContactModel& m = ctx.model;
  constexpr std::uint32_t kCount = Lanes<V>::kCount;
  const std::uint32_t* block = lists.neighbours + std::size_t(batch) * lists.stride;
  const std::uint32_t groups = grouped_length(batch_end(batch, end) - batch, kCount) / kCount;
  const std::uint32_t* const group_blocks = lists.blocks + batch / kCount;
  const std::uint32_t* const record = lists.records + 4 * std::size_t(batch);
  // Decided once per batch: most batches are in no fetch's window (all, on one thread).
  const std::uint32_t batch_number = batch / kStepBatch;
  const bool fetching = in_window(edges.rows[0], batch_number) || in_window(edges.rows[1], batch_number);
  const KindDamping kinds(m);
  // The blocks that need the whole law, of a group (at rest) or of the batch (moving).
  thread_local std::vector<WholeLawBlock> whole_law;
  whole_law.resize(std::max<std::size_t>(whole_law.size(), std::size_t(groups) * lists.stride + 1));
  // Asks for what later groups need, and loads the group's balls.
  const auto start_group = [&](std::uint32_t share) {
    if (ctx.plan.beyond_cache) prefetch_batch_ahead<kCount>(ctx, lists, batch, share);
    if (fetching)
      for (const RowFetch& f : edges.rows) fetch_rows<kCount>(s, f, batch_number, share);
    const std::uint32_t* const at = record + 4 * kCount * share + 3 * kCount;  // the group's list entries
    GroupBalls<V> i;
    i.kinds = &kinds;
    i.at = at;
    Lanes<V>::load(s.pos, at, i.x, i.y, i.z, i.r);
    Lanes<V>::load(s.vel_half, at, i.vx, i.vy, i.vz, i.inv_m);
    V unused;
    Lanes<V>::load(s.vel_half_before, at, i.bx, i.by, i.bz, unused);
    return i;
  };
  if (m.lead_bound < kStillLead) {  // each group in turn, its blocks that need the whole law after the rest
    for (std::uint32_t share = 0; share < groups; ++share) {
      GroupBalls<V> i = start_group(share);
      const std::uint32_t* const group_record = record + 4 * kCount * share;
      V f[3];
      WholeLawBlock* deferred = whole_law.data();
      neighbour_forces<false>(ctx, block, group_blocks[share], i, f[0], f[1], f[2], share, deferred);
      for (const WholeLawBlock* b = whole_law.data(); b < deferred; ++b) whole_law_forces(ctx, b->block, i, f);
      acceleration(ctx, i, f[0], f[1], f[2]);
      per_group(group_record + 3 * kCount, i, f[0], f[1], f[2], group_record);
      block += std::size_t(group_blocks[share]) * kCount;
    }
    return;
  }
  // Each group's balls and forces are held while the blocks that need the whole law are summed.
  constexpr std::uint32_t kGroups = kStepBatch / kCount;
  GroupBalls<V> balls[kGroups];
  V force[kGroups][3];
  WholeLawBlock* deferred = whole_law.data();
  for (std::uint32_t share = 0; share < groups; ++share) {
    balls[share] = start_group(share);
    V(&f)[3] = force[share];
    neighbour_forces<true>(ctx, block, group_blocks[share], balls[share], f[0], f[1], f[2], share, deferred);
    block += std::size_t(group_blocks[share]) * kCount;
  }
  for (const WholeLawBlock* b = whole_law.data(); b < deferred; ++b)
    whole_law_forces(ctx, b->block, balls[b->share], force[b->share]);
  for (std::uint32_t share = 0; share < groups; ++share) {
    const std::uint32_t* const group_record = record + 4 * kCount * share;
    V(&f)[3] = force[share];
    acceleration(ctx, balls[share], f[0], f[1], f[2]);
    per_group(group_record + 3 * kCount, balls[share], f[0], f[1], f[2], group_record);
  }
}

// The chunk's lead batches first (EdgeFetches::lead_begin), then the others in order.
template <class V, class PerGroup>
[[gnu::always_inline]] inline void for_each_group(const StepContext& ctx, const EdgeFetches& edges, std::uint32_t begin,
                                                  std::uint32_t end, PerGroup per_group) {
  const GroupLists lists = std::get<GroupLists>(ctx.arrays.lists);
  const bool led = edges.lead_begin < edges.lead_end;
  const std::uint32_t lead_begin = led ? edges.lead_begin : begin, lead_end = led ? edges.lead_end : begin;
  const std::uint32_t from[3] = {lead_begin, begin, lead_end}, to[3] = {lead_end, lead_begin, end};
  for (int part = 0; part < 3; ++part)
    for (std::uint32_t batch = from[part]; batch < to[part]; batch += kStepBatch)
      for_each_group_of_batch<V>(ctx, lists, edges, batch, end, per_group);
}

template <class V>
Moved step(const StepContext& context, std::uint32_t begin, std::uint32_t end) {
  // Local copies: stores through the output pointers cannot change them, so
  // pointers and constants stay in registers. The call takes the caller's
  // plan: a local whose address escaped would be reloaded after every store.
  const EdgeFetches edges = edge_fetches(context.plan, begin, end);
  const StepContext ctx = context;
  const StepArrays& s = ctx.arrays;
  const ContactModel& m = ctx.model;
  V max_d2 = V::zero(), max_v2 = V::zero();
  const V stray_d2 = V::splat(s.stray_d2);
  std::uint32_t* const stray_balls = s.stray_balls + begin;
  std::uint32_t strayed = 0;
  for_each_group<V>(
      ctx, edges, begin, end,
      [&](const std::uint32_t* at, const GroupBalls<V>& i, V ax, V ay, V az, const std::uint32_t* record) {
        const V half_dt = V::splat(m.half_dt), dt = V::splat(m.dt);
        const V vx = mul_add(ax, half_dt, i.vx), vy = mul_add(ay, half_dt, i.vy), vz = mul_add(az, half_dt, i.vz);
        const V hx = mul_add(ax, half_dt, vx), hy = mul_add(ay, half_dt, vy), hz = mul_add(az, half_dt, vz);
        Lanes<V>::store(hx, hy, hz, i.inv_m, s.vel_half_next, at);
        max_v2 = max(max_v2, mul_add(hz, hz, mul_add(hy, hy, hx * hx)));
        const V px = mul_add(hx, dt, i.x), py = mul_add(hy, dt, i.y), pz = mul_add(hz, dt, i.z);
        Lanes<V>::store(px, py, pz, i.r, s.pos_next, at);
        // Where the lanes' balls were at the build: the record's first three vectors.
        constexpr std::uint32_t kCount = Lanes<V>::kCount;
        V bx = V::load_bits(record), by = V::load_bits(record + kCount), bz = V::load_bits(record + 2 * kCount);
        bx -= px, by -= py, bz -= pz;
        const V d2 = mul_add(bz, bz, mul_add(by, by, bx * bx));
        max_d2 = max(max_d2, d2);
        if (int lanes = simd::bits(d2 > stray_d2)) [[unlikely]] {
          // A padded group repeats its last ball in the lanes after it: list it once.
          for (std::uint32_t l = 0; l < Lanes<V>::kCount; ++l, lanes >>= 1)
            if ((lanes & 1) && (l == 0 || at[l] != at[l - 1])) stray_balls[strayed++] = listed_index(at[l]);
        }
      });
  return Moved{Lanes<V>::largest(max_d2), Lanes<V>::largest(max_v2), strayed};
}

template <class V>
void accelerations(const StepContext& ctx, Float4* acc, std::uint32_t begin, std::uint32_t end) {
  for_each_group<V>(ctx, EdgeFetches{}, begin, end,
                    [&](const std::uint32_t* at, const GroupBalls<V>&, V ax, V ay, V az, const std::uint32_t*) {
                      Lanes<V>::store(ax, ay, az, V::zero(), acc, at);
                    });
}

}  // namespace
}  // namespace fishtank
