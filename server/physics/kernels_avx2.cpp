// AVX2 + FMA level of the step kernels. See kernels.h for the passes and
// kernels_scalar.cpp for the same arithmetic one pair at a time.
//
// Neighbour sums work as in the SSE kernel (kernels_sse.cpp), eight balls at
// a time: one ball per lane, each lane walking its own ball's list, so a
// block is one neighbour of each of eight balls, taken in order of their
// neighbour counts. AVX's shuffles work within 128-bit halves, so lanes l and
// l + 4 come from one paired load and the SSE 4x4 transpose serves both
// halves. The per-ball code (walls, kick, drift) carries two balls per
// vector, one per half. Multiply-adds are fused, so states agree with the
// other variants to float rounding, not bit for bit.

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

// Rows a[j[0..7]] as four vectors of lanes: x, y, z, w, with ball j[l] in
// lane l of the low half and j[l + 4] in lane l of the high half.
[[gnu::always_inline]] inline void lanes_of(const Float4* a, const std::uint32_t* j, F8& x, F8& y, F8& z, F8& w) {
  simd::transpose(F8::load_pair(a[j[0]], a[j[4]]), F8::load_pair(a[j[1]], a[j[5]]), F8::load_pair(a[j[2]], a[j[6]]),
                  F8::load_pair(a[j[3]], a[j[7]]), x, y, z, w);
}

// Sum over each ball's neighbours of the spring-dashpot force, as (Fx, Fy, Fz, 0).
void pair_forces(const StepArrays& arrays, const ContactModel& m, std::uint32_t first, std::uint32_t end,
                 Float4* forces) {
  const StepArrays s = arrays;  // a local copy: the stores to forces cannot change it (see step)
  const F8 k = F8::splat(m.k), damping = F8::splat(m.damping_factor);
  const F8 tiny = F8::splat(1e-12f);  // squared distance floor: coincident centres stay finite
  BatchOrder order(s, first, end, 8);
  for (const std::uint32_t* group = order.begin(); group < order.end(); group += 8) {
    F8 xi, yi, zi, ri, vxi, vyi, vzi, mi;
    lanes_of(s.pos, group, xi, yi, zi, ri);
    lanes_of(s.vel_half, group, vxi, vyi, vzi, mi);
    // Past its end, a shorter list's row holds the ghost: it touches nothing.
    const std::uint32_t* row[8];
    std::uint32_t longest = 0;
    for (int l = 0; l < 8; ++l) {
      row[l] = s.neighbours + std::size_t(group[l]) * s.stride;
      longest = std::max(longest, s.neighbour_count[group[l]]);
    }

    F8 fx = F8::zero(), fy = F8::zero(), fz = F8::zero();
    for (std::uint32_t n = 0; n < longest; ++n) {
      const std::uint32_t j[8] = {row[0][n], row[1][n], row[2][n], row[3][n],
                                  row[4][n], row[5][n], row[6][n], row[7][n]};
      F8 xj, yj, zj, rj, vxj, vyj, vzj, mj;
      lanes_of(s.pos, j, xj, yj, zj, rj);
      const F8 dx = xi - xj, dy = yi - yj, dz = zi - zj;
      const F8 d2 = mul_add(dz, dz, mul_add(dy, dy, dx * dx));
      const F8 reach = ri + rj;
      const M8 touching = d2 < reach * reach;
      lanes_of(s.vel_half, j, vxj, vyj, vzj, mj);
      const F8 inv_dist = simd::rsqrt(max(d2, tiny));
      const F8 dist = d2 * inv_dist;
      const F8 v_n_dist = mul_add(vzi - vzj, dz, mul_add(vyi - vyj, dy, (vxi - vxj) * dx));  // v_n |d|
      // sqrt(m_eff) = sqrt(mi mj / (mi + mj)) = mi mj / sqrt(mi mj (mi + mj)): one estimate, no reciprocal.
      const F8 mi_mj = mi * mj;
      const F8 c = damping * mi_mj * simd::rsqrt(mi_mj * (mi + mj));  // damping * sqrt(m_eff)
      // f / |d| multiplies the unnormalised d: the normal is never formed.
      const F8 f_over_dist = keep(touching, neg_mul_add(c, v_n_dist * inv_dist, k * (reach - dist)) * inv_dist);
      fx = mul_add(f_over_dist, dx, fx);
      fy = mul_add(f_over_dist, dy, fy);
      fz = mul_add(f_over_dist, dz, fz);
    }
    // The same transpose turns lanes back into rows: (Fx, Fy, Fz, 0) of ball group[l] | group[l + 4].
    F8 f0, f1, f2, f3;
    simd::transpose(fx, fy, fz, F8::zero(), f0, f1, f2, f3);
    f0.store_pair(forces[group[0] - first], forces[group[4] - first]);
    f1.store_pair(forces[group[1] - first], forces[group[5] - first]);
    f2.store_pair(forces[group[2] - first], forces[group[6] - first]);
    f3.store_pair(forces[group[3] - first], forces[group[7] - first]);
  }
}

}  // namespace

const Kernels kAvx2Kernels{
    "avx2", "avx2+fma", true, step<F8, pair_forces>, accelerations<F8, pair_forces>, build_lists_and_batch_order};

}  // namespace fishtank
