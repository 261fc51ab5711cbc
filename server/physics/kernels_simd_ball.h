#pragma once
// The parts of the SIMD kernels that work on one ball at a time in four lanes:
// walls, player spheres, the step pass around a neighbour loop that each
// kernel file supplies (4 lanes in kernels_sse.cpp, 8 in kernels_avx2.cpp),
// and the neighbour-list build.
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
struct Walls {
  F4 lo, hi;
  explicit Walls(const TankBounds& t)
      : lo(F4::set(t.min.x, t.min.y, t.min.z, -1e30f)), hi(F4::set(t.max.x, t.max.y, t.max.z, 1e30f)) {}
};

inline F4 wall_forces(const ContactModel& m, const Walls& walls, F4 pi, F4 vi) {
  const F4 r = simd::broadcast<3>(pi);
  const F4 below = walls.lo + r - pi;
  const F4 above = pi + r - walls.hi;
  const M4 in_floor_or_wall = below > F4::zero(), in_ceiling_or_wall = above > F4::zero();
  if (!simd::any(in_floor_or_wall | in_ceiling_or_wall)) return F4::zero();  // most balls touch no wall
  const F4 k = F4::splat(m.k);
  const F4 c = F4::splat(m.damping_factor) * sqrt(simd::broadcast<3>(vi));
  const F4 v = simd::xyz_only(vi);
  return keep(in_floor_or_wall, k * below - c * v) - keep(in_ceiling_or_wall, k * above + c * v);
}

// PairForces(s, m, i, p_i, v_i) sums the spring-dashpot forces of ball i's neighbours as (Fx, Fy, Fz, 0).
using PairForcesFn = F4 (*)(const StepArrays&, const ContactModel&, std::uint32_t, F4, F4);

// a = F / m + g for ball i at position pi with half-step velocity vi. Inlined
// into the ball loops so the contact constants stay in registers across balls.
template <PairForcesFn PairForces>
[[gnu::always_inline]] inline F4 acceleration(const StepArrays& s, const ContactModel& m, const Walls& walls,
                                              std::uint32_t i, F4 pi, F4 vi) {
  F4 force = PairForces(s, m, i, pi, vi) + wall_forces(m, walls, pi, vi);
  if (s.players > 0) force += player_forces(s, m, pi, vi);
  return force / simd::broadcast<3>(vi) + F4::set(0.0f, -m.gravity, 0.0f, 0.0f);  // force.w == 0, so a.w == 0
}

template <PairForcesFn PairForces>
float step(const StepArrays& s, const ContactModel& m, std::uint32_t begin, std::uint32_t end) {
  const F4 half_dt = F4::splat(m.half_dt);
  const F4 dt_xyz = F4::set(m.dt, m.dt, m.dt, 0.0f);  // keeps the radius in w
  const Walls walls(m.tank);
  F4 max_d2 = F4::zero();
  for (std::uint32_t i = begin; i < end; ++i) {
    const F4 pi = F4::load(s.pos[i]);
    const F4 vi = F4::load(s.vel_half[i]);
    const F4 a = acceleration<PairForces>(s, m, walls, i, pi, vi);
    const F4 v = vi + a * half_dt;
    const F4 vh_next = v + a * half_dt;
    const F4 p_next = pi + vh_next * dt_xyz;
    v.store(s.vel[i]);
    vh_next.store(s.vel_half_next[i]);
    p_next.store(s.pos_next[i]);
    const F4 d = p_next - F4::load(s.pos_at_build[i]);  // w lanes are both the radius
    max_d2 = max(max_d2, dot3(d, d));
  }
  return simd::lane(max_d2, 0);
}

template <PairForcesFn PairForces>
void accelerations(const StepArrays& s, const ContactModel& m, Float4* acc, std::uint32_t begin, std::uint32_t end) {
  const Walls walls(m.tank);
  for (std::uint32_t i = begin; i < end; ++i)
    acceleration<PairForces>(s, m, walls, i, F4::load(s.pos[i]), F4::load(s.vel_half[i])).store(acc[i]);
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

}  // namespace
}  // namespace fishtank
