#pragma once
// What the two SIMD kernel files share, written once for a vector type V:
// the step and acceleration passes (the list build: kernels_simd_lists.h;
// what the step asks memory for ahead: kernels_simd_prefetch.h). A vector
// carries a group of balls, one per lane (four in F4, eight in F8), and each
// lane walks its own ball's list, one neighbour per block; each kernel file
// says how to gather and scatter its lanes (Lanes<V>). Both files compile this
// with different -m flags, so everything here has internal linkage: the linker
// can never hand AVX2 code to the SSE build.

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "server/physics/contact_law.h"
#include "server/physics/kernels.h"
#include "server/physics/kernels_simd_lists.h"
#include "server/physics/kernels_simd_prefetch.h"

namespace fishtank {
namespace {

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
