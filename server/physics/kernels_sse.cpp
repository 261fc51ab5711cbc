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

#include "server/physics/kernels_simd_ball.h"

namespace fishtank {
namespace {

// Sum over ball i's neighbours of the spring-dashpot force, as (Fx, Fy, Fz, 0).
[[gnu::always_inline]] inline F4 pair_forces(const StepArrays& s, const ContactModel& m, std::uint32_t i,
                                             std::uint32_t /*last: i, one ball per vector*/, F4 pi, F4 vi) {
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
  const std::uint32_t count = padded_neighbour_count(s.neighbour_count[i], 4);
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
    F4 v_n_dist = dvx * dx + dvy * dy + dvz * dz;  // v_n |d|
    // sqrt(m_eff) = sqrt(mi mj / (mi + mj)) = mi mj / sqrt(mi mj (mi + mj)): one estimate, no reciprocal.
    F4 mj = mi - mi_minus_mj;
    F4 mi_mj = mi * mj;
    F4 c = damping * mi_mj * simd::rsqrt(mi_mj * (mi + mj));  // damping * sqrt(m_eff)
    // f / |d| multiplies the unnormalised d: the normal is never formed.
    F4 f_over_dist = keep(touching, (k * (reach - dist) - c * (v_n_dist * inv_dist)) * inv_dist);
    fx += f_over_dist * dx;
    fy += f_over_dist * dy;
    fz += f_over_dist * dz;
  }
  return simd::sum_lanes_xyz(fx, fy, fz);
}

}  // namespace

const Kernels kSseKernels{"sse", "sse4.1", true, step<F4, pair_forces>, accelerations<F4, pair_forces>, build_lists};

}  // namespace fishtank
