#pragma once
// The parts of the SIMD kernels that work per ball: walls, player spheres,
// the step pass around the neighbour sums that each kernel file supplies, and
// the neighbour-list build.
//
// For the per-ball arithmetic (walls, kick, drift) a vector V carries one
// ball in four lanes (F4, kernels_sse.cpp) or two balls, one per 128-bit half
// (F8, kernels_avx2.cpp); BallLanes<V> says how to load and store them.
//
// Both files include this header and are compiled with different -m flags, so
// everything here has internal linkage: each gets its own copy in its own
// instruction set, and the linker can never hand AVX2 code to the SSE build.

#include <algorithm>

#include "common/simd/sse_float4.h"
#include "server/physics/kernels.h"

namespace fishtank {
namespace {

using simd::F4;
using simd::M4;

// How a vector type holds balls. A pass visits balls first..last together
// (last == first when a chunk's last ball has no partner: it is then carried
// twice and stored twice, with the same result).
template <class V>
struct BallLanes;

template <>
struct BallLanes<F4> {
  static constexpr std::uint32_t kBalls = 1;
  static F4 both(F4 a) { return a; }
  static F4 load(const Float4* a, std::uint32_t first, std::uint32_t) { return F4::load(a[first]); }
  static void store(F4 v, Float4* a, std::uint32_t first, std::uint32_t) { v.store(a[first]); }
  template <class PerBall>
  static F4 each_ball(PerBall f, F4 p, F4 v) {
    return f(p, v);
  }
  static float lane0_max(F4 a) { return simd::lane(a, 0); }  // lane 0, the largest over the balls carried
};

// Kinematic player spheres: the ball's effective mass is its own mass.
inline F4 player_forces(const StepArrays& s, const ContactModel& m, F4 pi, F4 vi) {
  F4 force = F4::zero();
  const float ri = simd::lane(pi, 3);
  const F4 c = F4::splat(m.damping_factor) * sqrt(simd::broadcast<3>(vi));
  for (int p = 0; p < s.players; ++p) {
    F4 d = simd::xyz_only(pi - F4::load(s.player_pos[p]));
    float reach = ri + s.player_pos[p].w;
    F4 d2 = dot3(d, d);
    if (simd::lane(d2, 0) >= reach * reach) continue;
    F4 dist = max(sqrt(d2), F4::splat(1e-6f));
    F4 n = d / dist;
    F4 v_n = dot3(vi - F4::load(s.player_vel[p]), n);
    force += (F4::splat(m.k) * (F4::splat(reach) - dist) - c * v_n) * n;
  }
  return force;
}

// Six half-space walls, one lane per axis: below the minimum face the force
// points +axis, above the maximum face -axis; both grow with depth. The w
// lanes of the faces are chosen so the w lane never registers a contact.
template <class V>
struct Walls {
  V lo, hi;
  explicit Walls(const TankBounds& t)
      : lo(BallLanes<V>::both(F4::set(t.min.x, t.min.y, t.min.z, -1e30f))),
        hi(BallLanes<V>::both(F4::set(t.max.x, t.max.y, t.max.z, 1e30f))) {}
};

template <class V>
inline V wall_forces(const ContactModel& m, const Walls<V>& walls, V pi, V vi) {
  const V r = simd::broadcast<3>(pi);
  const V below = walls.lo + r - pi;
  const V above = pi + r - walls.hi;
  const auto in_floor_or_wall = below > V::zero(), in_ceiling_or_wall = above > V::zero();
  if (!simd::any(in_floor_or_wall | in_ceiling_or_wall)) return V::zero();  // most balls touch no wall
  const V k = V::splat(m.k);
  const V c = V::splat(m.damping_factor) * sqrt(simd::broadcast<3>(vi));
  const V v = simd::xyz_only(vi);
  return keep(in_floor_or_wall, k * below - c * v) - keep(in_ceiling_or_wall, k * above + c * v);
}

// PairForces(s, m, first, end, forces) sums the spring-dashpot forces of the
// neighbours of each ball b in [first, end), a batch of at most kStepBatch, into
// forces[b - first] as (Fx, Fy, Fz, 0). Each kernel file supplies its own.
using PairForcesFn = void (*)(const StepArrays&, const ContactModel&, std::uint32_t, std::uint32_t, Float4*);

// a = F / m + g for the balls in p (positions) and v (half-step velocities),
// given the sums of their neighbours' forces: adds walls and player spheres.
template <class V>
[[gnu::always_inline]] inline V acceleration(const StepArrays& s, const ContactModel& m, const Walls<V>& walls, V p,
                                             V v, V pair_force) {
  V force = pair_force + wall_forces(m, walls, p, v);
  if (s.players > 0) force += BallLanes<V>::each_ball([&](F4 pi, F4 vi) { return player_forces(s, m, pi, vi); }, p, v);
  // force.w == 0, so a.w == 0
  return force / simd::broadcast<3>(v) + BallLanes<V>::both(F4::set(0.0f, -m.gravity, 0.0f, 0.0f));
}

// Balls are stepped in batches of kStepBatch (kernels.h): first the neighbour
// sums of the whole batch, then the rest for each ball. Neither loop then
// keeps the other's values in registers, and the neighbour loops of a batch
// run back to back: faster than one loop doing both, although it executes a
// few more instructions (technical report, section 4).
// per_balls(first, last, pair_force) gets the balls of V one after another.
template <class V, PairForcesFn PairForces, class PerBalls>
[[gnu::always_inline]] inline void for_each_batch(const StepArrays& s, const ContactModel& m, std::uint32_t begin,
                                                  std::uint32_t end, PerBalls per_balls) {
  using Lanes = BallLanes<V>;
  alignas(32) Float4 pair_force[kStepBatch];
  for (std::uint32_t batch = begin, last_of_batch; batch < end; batch = last_of_batch) {
    last_of_batch = batch_end(batch, end);
    PairForces(s, m, batch, last_of_batch, pair_force);
    for (std::uint32_t first = batch; first < last_of_batch; first += Lanes::kBalls) {
      const std::uint32_t last = std::min(first + Lanes::kBalls, last_of_batch) - 1;
      per_balls(first, last, Lanes::load(pair_force, first - batch, last - batch));
    }
  }
}

template <class V, PairForcesFn PairForces>
float step(const StepArrays& arrays, const ContactModel& model, std::uint32_t begin, std::uint32_t end) {
  using Lanes = BallLanes<V>;
  // Local copies: stores through the output pointers cannot change them, so
  // pointers and constants stay in registers instead of being reloaded per ball.
  const StepArrays s = arrays;
  const ContactModel m = model;
  const V half_dt = V::splat(m.half_dt);
  const V dt_xyz = Lanes::both(F4::set(m.dt, m.dt, m.dt, 0.0f));  // keeps the radius in w
  const Walls<V> walls(m.tank);
  V max_d2 = V::zero();
  for_each_batch<V, PairForces>(s, m, begin, end, [&](std::uint32_t first, std::uint32_t last, V pair_force) {
    const V p = Lanes::load(s.pos, first, last);
    const V vh = Lanes::load(s.vel_half, first, last);
    const V a = acceleration(s, m, walls, p, vh, pair_force);
    const V v = vh + a * half_dt;
    const V vh_next = v + a * half_dt;
    const V p_next = p + vh_next * dt_xyz;
    Lanes::store(v, s.vel, first, last);
    Lanes::store(vh_next, s.vel_half_next, first, last);
    Lanes::store(p_next, s.pos_next, first, last);
    const V d = p_next - Lanes::load(s.pos_at_build, first, last);  // w lanes are both the radius
    max_d2 = max(max_d2, dot3(d, d));
  });
  return Lanes::lane0_max(max_d2);
}

template <class V, PairForcesFn PairForces>
void accelerations(const StepArrays& s, const ContactModel& m, Float4* acc, std::uint32_t begin, std::uint32_t end) {
  using Lanes = BallLanes<V>;
  const Walls<V> walls(m.tank);
  for_each_batch<V, PairForces>(s, m, begin, end, [&](std::uint32_t first, std::uint32_t last, V pair_force) {
    const V p = Lanes::load(s.pos, first, last), v = Lanes::load(s.vel_half, first, last);
    Lanes::store(acceleration(s, m, walls, p, v, pair_force), acc, first, last);
  });
}

// Lists four candidates at a time: a cell range is contiguous in the sorted
// arrays, so four consecutive balls are tested at once and the indices of
// those within reach are packed into the list with one byte shuffle, with no
// branch per candidate (the scalar build mispredicts on most of them).
inline std::uint32_t build_lists(const ListBuild& b, std::uint32_t begin, std::uint32_t end) {
  const F4 skin = F4::splat(b.skin);
  std::uint32_t longest = 0;
  for (std::uint32_t i = begin; i < end; ++i) {
    const F4 pi = F4::load(b.pos[i]);
    const F4 two_ri_skin = simd::broadcast<3>(pi) + simd::broadcast<3>(pi) + skin;
    const simd::I4 self = simd::I4::splat(i);
    std::uint32_t* list = b.neighbours + std::size_t(i) * b.stride;
    std::uint32_t count = 0;
    for_each_neighbour_range(b, i, [&](std::uint32_t j_begin, std::uint32_t j_end) {
      const simd::I4 range_end = simd::I4::splat(j_end);
      for (std::uint32_t j = j_begin; j < j_end; j += 4) {  // may read up to 3 ghosts past the end
        F4 dx, dy, dz, ri_minus_rj;
        simd::transpose(pi - F4::load(b.pos[j]), pi - F4::load(b.pos[j + 1]), pi - F4::load(b.pos[j + 2]),
                        pi - F4::load(b.pos[j + 3]), dx, dy, dz, ri_minus_rj);
        const F4 cutoff = two_ri_skin - ri_minus_rj;  // ri + rj + skin
        const simd::I4 index = simd::I4::iota(j);
        int found = bits((dx * dx + dy * dy + dz * dz < cutoff * cutoff) & (index < range_end) & (index != self));
        if (found == 0) continue;
        if (count + 4 > b.stride) {  // nearly full: one by one, counting on so the caller can grow the list
          for (std::uint32_t lane = 0; lane < 4; ++lane, found >>= 1)
            if (found & 1) {
              if (count < b.stride) list[count] = j + lane;
              ++count;
            }
          continue;
        }
        compress_store(index, found, list + count);
        count += __builtin_popcount(found);
      }
    });
    longest = std::max(longest, finish_list(b, i, count));
  }
  return longest;
}

// Balls first..end-1 of a batch, by neighbour count (a counting sort), padded
// to a multiple of `lanes` with the last one repeated: a repeated ball is
// computed twice and stored twice, with the same result. Returns the length.
// Both SIMD kernels take one ball per lane and one neighbour of each per
// block, so a group costs as many blocks as its longest list; grouping balls
// of equal counts keeps the blocks full (kernels_sse.cpp).
inline std::uint32_t by_neighbour_count(const std::uint32_t* counts, std::uint32_t first, std::uint32_t end,
                                        std::uint32_t lanes, std::uint32_t* order) {
  constexpr std::uint32_t kBuckets = 32;  // longer lists share the last bucket: only the grouping is coarser
  std::uint32_t start[kBuckets + 1] = {};
  for (std::uint32_t b = first; b < end; ++b) ++start[std::min(counts[b], kBuckets - 1) + 1];
  for (std::uint32_t c = 1; c <= kBuckets; ++c) start[c] += start[c - 1];
  for (std::uint32_t b = first; b < end; ++b) order[start[std::min(counts[b], kBuckets - 1)]++] = b;
  std::uint32_t n = end - first;
  for (; n % lanes != 0; ++n) order[n] = order[n - 1];
  return n;
}

// The SIMD build, then the order of every whole batch of the range, so that
// the step passes until the next build need not sort (sorting every step cost
// 8 % of the SSE step). A batch cut by the range's end, the last of the balls,
// is sorted by the step itself. kStepBatch is a multiple of every lane count.
inline std::uint32_t build_lists_and_batch_order(const ListBuild& b, std::uint32_t begin, std::uint32_t end) {
  const std::uint32_t longest = build_lists(b, begin, end);
  for (std::uint32_t batch = begin; batch + kStepBatch <= end; batch += kStepBatch)
    by_neighbour_count(b.counts, batch, batch + kStepBatch, 1, b.batch_order + batch);
  return longest;
}

// The balls of batch [first, end) by neighbour count, in groups of `lanes`
// (at most 8): the order the list build wrote for a whole batch, or one
// sorted here for a batch cut short.
class BatchOrder {
 public:
  BatchOrder(const StepArrays& s, std::uint32_t first, std::uint32_t end, std::uint32_t lanes)
      : begin_(s.batch_order + first), length_(kStepBatch) {
    if (end - first == kStepBatch) return;
    length_ = by_neighbour_count(s.neighbour_count, first, end, lanes, sorted_here_);
    begin_ = sorted_here_;
  }
  const std::uint32_t* begin() const { return begin_; }
  const std::uint32_t* end() const { return begin_ + length_; }

 private:
  std::uint32_t sorted_here_[kStepBatch + 7];
  const std::uint32_t* begin_;
  std::uint32_t length_;
};

}  // namespace
}  // namespace fishtank
