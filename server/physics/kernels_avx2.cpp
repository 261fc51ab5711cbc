// AVX2 + FMA level of the step kernels: two balls per 256-bit vector, one in
// each 128-bit half. See kernels.h for the passes and kernels_scalar.cpp for
// the same arithmetic one pair at a time.
//
// Each half takes four of its ball's neighbours per block, loaded, transposed
// and computed at once. A block therefore covers four neighbours of ball a
// and four of ball b, and the per-ball work around the neighbour loop (loads,
// walls, kick, drift, stores, the sum over lanes) is done for two balls per
// instruction. A ball has 7.5 neighbours on average, so the pairs' blocks are
// about as well filled as blocks of eight neighbours of one ball. The arithmetic is the SSE kernel's,
// with multiply-adds fused, so states agree with the other variants to float
// rounding, not bit for bit.

#include "common/simd/avx_float8.h"
#include "server/physics/kernels_simd_ball.h"

namespace fishtank {
namespace {

using simd::F8;
using simd::M8;

template <>
struct BallLanes<F8> {
  static constexpr std::uint32_t kBalls = 2;
  static F8 both(F4 a) { return F8::both(a); }
  static F8 load(const Float4* a, std::uint32_t first, std::uint32_t last) { return F8::load_pair(a[first], a[last]); }
  static void store(F8 v, Float4* a, std::uint32_t first, std::uint32_t last) { v.store_pair(a[first], a[last]); }
  template <class PerBall>
  static F8 each_ball(PerBall f, F8 p, F8 v) {
    return F8::halves(f(p.lo(), v.lo()), f(p.hi(), v.hi()));
  }
  static float lane0_max(F8 a) { return simd::lane(max(a.lo(), a.hi()), 0); }
};

// Sum over the neighbours of balls a (low half of p, v) and b (high half) of
// the spring-dashpot force, as (Fx, Fy, Fz, 0) in each half.
[[gnu::always_inline]] inline F8 pair_forces_of_two(const StepArrays& s, const ContactModel& m, std::uint32_t a,
                                                    std::uint32_t b, F8 p, F8 v) {
  // Rows are subtracted before the transpose, so only p, v and two broadcasts
  // stay live: p - pos[j] is (dx, dy, dz, ri - rj), v - vel[j] is (dvx, dvy, dvz, mi - mj).
  const F8 two_ri = simd::broadcast<3>(p) + simd::broadcast<3>(p);
  const F8 mi = simd::broadcast<3>(v);
  const F8 k = F8::splat(m.k), damping = F8::splat(m.damping_factor);
  const F8 tiny = F8::splat(1e-12f);  // squared distance floor: coincident centres stay finite

  // Past its end, the shorter list's row holds ghosts: they touch nothing.
  const std::uint32_t* list_a = s.neighbours + std::size_t(a) * s.stride;
  const std::uint32_t* list_b = s.neighbours + std::size_t(b) * s.stride;
  const std::uint32_t count = padded_neighbour_count(std::max(s.neighbour_count[a], s.neighbour_count[b]), 4);

  F8 fx = F8::zero(), fy = F8::zero(), fz = F8::zero();
  for (std::uint32_t n = 0; n < count; n += 4) {
    const std::uint32_t* ja = list_a + n;
    const std::uint32_t* jb = list_b + n;
    F8 dx, dy, dz, ri_minus_rj;
    simd::transpose(p - F8::load_pair(s.pos[ja[0]], s.pos[jb[0]]), p - F8::load_pair(s.pos[ja[1]], s.pos[jb[1]]),
                    p - F8::load_pair(s.pos[ja[2]], s.pos[jb[2]]), p - F8::load_pair(s.pos[ja[3]], s.pos[jb[3]]), dx,
                    dy, dz, ri_minus_rj);
    F8 d2 = mul_add(dz, dz, mul_add(dy, dy, dx * dx));
    F8 reach = two_ri - ri_minus_rj;  // ri + rj
    M8 touching = d2 < reach * reach;
    if (!simd::any(touching)) continue;

    F8 dvx, dvy, dvz, mi_minus_mj;
    simd::transpose(v - F8::load_pair(s.vel_half[ja[0]], s.vel_half[jb[0]]),
                    v - F8::load_pair(s.vel_half[ja[1]], s.vel_half[jb[1]]),
                    v - F8::load_pair(s.vel_half[ja[2]], s.vel_half[jb[2]]),
                    v - F8::load_pair(s.vel_half[ja[3]], s.vel_half[jb[3]]), dvx, dvy, dvz, mi_minus_mj);
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
  return simd::sum_lanes_xyz(fx, fy, fz);
}

// The batch two balls at a time; an odd batch's last ball is carried in both
// halves and stored twice, with the same result.
void pair_forces(const StepArrays& arrays, const ContactModel& model, std::uint32_t first, std::uint32_t end,
                 Float4* forces) {
  const StepArrays s = arrays;  // local copies: the stores to forces cannot change them (see step)
  const ContactModel m = model;
  for (std::uint32_t a = first; a < end; a += 2) {
    const std::uint32_t b = std::min(a + 1, end - 1);
    const F8 p = F8::load_pair(s.pos[a], s.pos[b]), v = F8::load_pair(s.vel_half[a], s.vel_half[b]);
    pair_forces_of_two(s, m, a, b, p, v).store_pair(forces[a - first], forces[b - first]);
  }
}

}  // namespace

const Kernels kAvx2Kernels{"avx2",     "avx2+fma", true, step<F8, pair_forces>, accelerations<F8, pair_forces>,
                           build_lists};

}  // namespace fishtank
