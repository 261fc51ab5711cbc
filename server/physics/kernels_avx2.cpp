// AVX2 + FMA level of the step kernels: the SSE neighbour loop of
// kernels_sse.cpp widened to eight neighbours per block. See kernels.h for the
// passes and kernels_scalar.cpp for the same arithmetic one pair at a time.
//
// A settled ball has 7.5 listed neighbours, so most lists are one block of
// eight instead of two or three blocks of four: fewer transposes, fewer
// Newton steps, less padding. Neighbours j0..j3 sit in the low half of each
// register and j4..j7 in the high half (see common/simd/avx_float8.h); the
// arithmetic is the SSE kernel's, with multiply-adds fused, so states agree
// with the other variants to float rounding, not bit for bit.

#include "common/simd/avx_float8.h"
#include "server/physics/kernels_simd_ball.h"

namespace fishtank {
namespace {

using simd::F8;
using simd::M8;

// Sum over ball i's neighbours of the spring-dashpot force, as (Fx, Fy, Fz, 0).
[[gnu::always_inline]] inline F4 pair_forces(const StepArrays& s, const ContactModel& m, std::uint32_t i, F4 pi4,
                                             F4 vi4) {
  // As in the SSE kernel, rows are subtracted before the transpose:
  // pi - pos[j] is (dx, dy, dz, ri - rj), vi - vel[j] is (dvx, dvy, dvz, mi - mj).
  const F8 pi = F8::both(pi4), vi = F8::both(vi4);
  const F8 two_ri = simd::broadcast<3>(pi) + simd::broadcast<3>(pi);
  const F8 mi = simd::broadcast<3>(vi);
  const F8 k = F8::splat(m.k), damping = F8::splat(m.damping_factor);
  const F8 tiny = F8::splat(1e-12f);  // squared distance floor: coincident centres stay finite

  F8 fx = F8::zero(), fy = F8::zero(), fz = F8::zero();
  const std::uint32_t* list = s.neighbours + std::size_t(i) * s.stride;
  const std::uint32_t count = padded_neighbour_count(s.neighbour_count[i], 8);
  for (std::uint32_t n = 0; n < count; n += 8) {
    const std::uint32_t* j = list + n;
    F8 dx, dy, dz, ri_minus_rj;
    simd::transpose(pi - F8::load_pair(s.pos[j[0]], s.pos[j[4]]), pi - F8::load_pair(s.pos[j[1]], s.pos[j[5]]),
                    pi - F8::load_pair(s.pos[j[2]], s.pos[j[6]]), pi - F8::load_pair(s.pos[j[3]], s.pos[j[7]]), dx, dy,
                    dz, ri_minus_rj);
    F8 d2 = mul_add(dz, dz, mul_add(dy, dy, dx * dx));
    F8 reach = two_ri - ri_minus_rj;  // ri + rj
    M8 touching = d2 < reach * reach;
    if (!simd::any(touching)) continue;

    F8 dvx, dvy, dvz, mi_minus_mj;
    simd::transpose(vi - F8::load_pair(s.vel_half[j[0]], s.vel_half[j[4]]),
                    vi - F8::load_pair(s.vel_half[j[1]], s.vel_half[j[5]]),
                    vi - F8::load_pair(s.vel_half[j[2]], s.vel_half[j[6]]),
                    vi - F8::load_pair(s.vel_half[j[3]], s.vel_half[j[7]]), dvx, dvy, dvz, mi_minus_mj);
    F8 inv_dist = simd::rsqrt(max(d2, tiny));
    F8 dist = d2 * inv_dist;
    F8 v_n_dist = mul_add(dvz, dz, mul_add(dvy, dy, dvx * dx));  // v_n |d|
    // sqrt(m_eff) = sqrt(mi mj / (mi + mj)) = mi mj / sqrt(mi mj (mi + mj)): one estimate, no reciprocal.
    F8 mj = mi - mi_minus_mj;
    F8 mi_mj = mi * mj;
    F8 c = damping * mi_mj * simd::rsqrt(mi_mj * (mi + mj));  // damping * sqrt(m_eff)
    // f / |d| multiplies the unnormalised d: the normal is never formed.
    F8 f_over_dist = keep(touching, neg_mul_add(c, v_n_dist * inv_dist, k * (reach - dist)) * inv_dist);
    fx = mul_add(f_over_dist, dx, fx);
    fy = mul_add(f_over_dist, dy, fy);
    fz = mul_add(f_over_dist, dz, fz);
  }
  return simd::sum_lanes_xyz(fold_halves(fx), fold_halves(fy), fold_halves(fz));
}

}  // namespace

const Kernels kAvx2Kernels{"avx2", "avx2+fma", 8, true, step<pair_forces>, accelerations<pair_forces>, build_lists};

}  // namespace fishtank
