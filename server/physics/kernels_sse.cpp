// SSE4.1 twin of the step kernels. See kernels.h for the passes and
// kernels_scalar.cpp for the same arithmetic one pair at a time.
//
// Neighbours are taken four at a time: four aligned loads of (x, y, z, r),
// a 4x4 transpose, and the contact arithmetic runs on four pairs per
// instruction. Velocities are loaded and transposed only when at least one of
// the four touches, which in a settled pile skips about half of the blocks.
// 1/|d| and sqrt(m_eff) come from the reciprocal-square-root estimate plus a
// Newton step (1e-7 relative) instead of sqrt and divide; the scalar twin
// computes them exactly, so the twins agree to float rounding, not bit for bit.

#include "common/simd/sse_float4.h"
#include "server/physics/kernels.h"

namespace fishtank {
namespace {

using simd::F4;
using simd::M4;

float kick_drift(const StepArrays& s, const ContactModel& m, std::uint32_t begin, std::uint32_t end) {
  const F4 half_dt = F4::splat(m.half_dt);
  const F4 dt_xyz = F4::set(m.dt, m.dt, m.dt, 0.0f);
  F4 max_d2 = F4::zero();
  for (std::uint32_t i = begin; i < end; ++i) {
    F4 vh = F4::load(s.vel[i]) + F4::load(s.acc[i]) * half_dt;  // acc.w == 0 keeps the mass
    F4 p = F4::load(s.pos[i]) + vh * dt_xyz;
    vh.store(s.vel_half[i]);
    p.store(s.pos[i]);
    F4 d = p - F4::load(s.pos_at_build[i]);  // w lanes are both the radius
    max_d2 = max(max_d2, dot3(d, d));
  }
  return simd::lane(max_d2, 0);
}

// Sum over ball i's neighbours of the spring-dashpot force, as (Fx, Fy, Fz, 0).
inline F4 pair_forces(const StepArrays& s, const ContactModel& m, std::uint32_t i, F4 pi, F4 vi) {
  // Differences are taken on whole rows before the transpose: pi - pos[j] is
  // (dx, dy, dz, ri - rj) and vi - vel[j] is (dvx, dvy, dvz, mi - mj). That
  // keeps only pi, vi and two broadcasts live instead of eight, so SSE's 16
  // registers hold the loop without spilling to the stack.
  const F4 two_ri = simd::broadcast<3>(pi) + simd::broadcast<3>(pi);
  const F4 mi = simd::broadcast<3>(vi);
  const F4 k = F4::splat(m.k), damping = F4::splat(m.damping_factor);
  const F4 tiny = F4::splat(1e-12f);  // squared distance floor: coincident centres stay finite

  F4 fx = F4::zero(), fy = F4::zero(), fz = F4::zero();
  const std::uint32_t* list = s.neighbours + std::size_t(i) * s.stride;
  const std::uint32_t count = padded_neighbour_count(s.neighbour_count[i]);
  for (std::uint32_t n = 0; n < count; n += 4) {
    const std::uint32_t j0 = list[n], j1 = list[n + 1], j2 = list[n + 2], j3 = list[n + 3];
    F4 dx, dy, dz, ri_minus_rj;
    simd::transpose(pi - F4::load(s.pos[j0]), pi - F4::load(s.pos[j1]), pi - F4::load(s.pos[j2]),
                    pi - F4::load(s.pos[j3]), dx, dy, dz, ri_minus_rj);
    F4 d2 = dx * dx + dy * dy + dz * dz;
    F4 reach = two_ri - ri_minus_rj;  // ri + rj
    M4 touching = d2 < reach * reach;
    if (!simd::any(touching)) continue;

    F4 dvx, dvy, dvz, mi_minus_mj;
    simd::transpose(vi - F4::load(s.vel_half[j0]), vi - F4::load(s.vel_half[j1]), vi - F4::load(s.vel_half[j2]),
                    vi - F4::load(s.vel_half[j3]), dvx, dvy, dvz, mi_minus_mj);
    F4 inv_dist = simd::rsqrt(max(d2, tiny));
    F4 dist = d2 * inv_dist;
    F4 nx = dx * inv_dist, ny = dy * inv_dist, nz = dz * inv_dist;
    F4 v_n = dvx * nx + dvy * ny + dvz * nz;
    F4 mj = mi - mi_minus_mj;
    F4 m_eff = mi * mj * simd::reciprocal(mi + mj);
    F4 c = damping * m_eff * simd::rsqrt(m_eff);  // damping * sqrt(m_eff)
    F4 f = keep(touching, k * (reach - dist) - c * v_n);
    fx += f * nx;
    fy += f * ny;
    fz += f * nz;
  }
  return simd::sum_lanes_xyz(fx, fy, fz);
}

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

void forces_kick(const StepArrays& s, const ContactModel& m, std::uint32_t begin, std::uint32_t end) {
  const F4 gravity = F4::set(0.0f, -m.gravity, 0.0f, 0.0f);
  const F4 half_dt = F4::splat(m.half_dt);
  const Walls walls(m.tank);
  for (std::uint32_t i = begin; i < end; ++i) {
    const F4 pi = F4::load(s.pos[i]);
    const F4 vi = F4::load(s.vel_half[i]);
    F4 force = pair_forces(s, m, i, pi, vi) + wall_forces(m, walls, pi, vi);
    if (s.players > 0) force += player_forces(s, m, pi, vi);
    F4 a = force / simd::broadcast<3>(vi) + gravity;  // force.w == 0, so a.w == 0
    a.store(s.acc[i]);
    (vi + a * half_dt).store(s.vel[i]);
  }
}

}  // namespace

// The same source, compiled a second time with -mavx2 -mfma (see
// server/CMakeLists.txt), is the third level: identical arithmetic on the same
// 4 lanes, but VEX three-operand encoding removes most register copies and
// spills (callgrind: 26% fewer instructions in forces_kick).
#if defined(__AVX2__)
const Kernels kAvx2Kernels{"avx2", "avx2 (4 lanes, VEX)", true, kick_drift, forces_kick};
#else
const Kernels kSseKernels{"sse", "sse4.1", true, kick_drift, forces_kick};
#endif

}  // namespace fishtank
