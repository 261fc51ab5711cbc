// SSE4.1 twin of the step kernels. See kernels.h for the passes and
// kernels_scalar.cpp for the same arithmetic one pair at a time.
//
// Neighbour sums take four balls at a time, one per lane, and each lane walks
// its own ball's list: a block is one neighbour of each of the four, loaded,
// transposed, and computed at once. Per lane, a ball's forces are added in
// list order, as in the scalar twin, and no sum over lanes is needed at the
// end. A group of four costs as many blocks as its longest list, so the balls
// of a batch are taken in order of their neighbour counts: on the settled tank
// that is 1.95 blocks per ball, against 2.20 for one ball's neighbours four at
// a time (technical report, section 4). Velocities are loaded for every
// block: in a pile, 99 % of blocks have at least one lane in contact.
// 1/|d| and sqrt(m_eff) come from the reciprocal-square-root estimate plus a
// Newton step (1e-7 relative) instead of sqrt and divide; the scalar twin
// computes them exactly, so the twins agree to float rounding, not bit for bit.

#include "server/physics/kernels_simd_ball.h"

namespace fishtank {
namespace {

// Sum over each ball's neighbours of the spring-dashpot force, as (Fx, Fy, Fz, 0).
void pair_forces(const StepArrays& arrays, const ContactModel& m, std::uint32_t first, std::uint32_t end,
                 Float4* forces) {
  const StepArrays s = arrays;  // a local copy: the stores to forces cannot change it (see step)
  const F4 k = F4::splat(m.k), neg_damping = F4::splat(-m.damping_factor);
  const F4 tiny = F4::splat(1e-12f);  // squared distance floor: coincident centres stay finite
  BatchOrder order(s, first, end, 4);
  for (const std::uint32_t* group = order.begin(); group < order.end(); group += 4) {
    const std::uint32_t a = group[0], b = group[1], c = group[2], d = group[3];
    F4 xi, yi, zi, ri, vxi, vyi, vzi, mi;
    simd::transpose(F4::load(s.pos[a]), F4::load(s.pos[b]), F4::load(s.pos[c]), F4::load(s.pos[d]), xi, yi, zi, ri);
    simd::transpose(F4::load(s.vel_half[a]), F4::load(s.vel_half[b]), F4::load(s.vel_half[c]), F4::load(s.vel_half[d]),
                    vxi, vyi, vzi, mi);
    // Past its end, a shorter list's row holds the ghost: it touches nothing.
    const std::uint32_t* row_a = s.neighbours + std::size_t(a) * s.stride;
    const std::uint32_t* row_b = s.neighbours + std::size_t(b) * s.stride;
    const std::uint32_t* row_c = s.neighbours + std::size_t(c) * s.stride;
    const std::uint32_t* row_d = s.neighbours + std::size_t(d) * s.stride;
    const std::uint32_t longest = std::max(std::max(s.neighbour_count[a], s.neighbour_count[b]),
                                           std::max(s.neighbour_count[c], s.neighbour_count[d]));

    F4 fx = F4::zero(), fy = F4::zero(), fz = F4::zero();
    for (std::uint32_t n = 0; n < longest; ++n) {
      const std::uint32_t ja = row_a[n], jb = row_b[n], jc = row_c[n], jd = row_d[n];
      // d and dv point from ball i to its neighbour, the opposite of the scalar
      // twin's: SSE's two-operand subtract then needs no copy of ball i's lanes.
      // Negations are exact, and below they cancel in pairs, so every value is
      // the scalar formula's (up to the estimates).
      F4 dx, dy, dz, rj;
      simd::transpose(F4::load(s.pos[ja]), F4::load(s.pos[jb]), F4::load(s.pos[jc]), F4::load(s.pos[jd]), dx, dy, dz,
                      rj);
      dx -= xi, dy -= yi, dz -= zi;
      const F4 d2 = dx * dx + dy * dy + dz * dz;
      const F4 reach = rj + ri;
      const M4 touching = d2 < reach * reach;

      F4 dvx, dvy, dvz, mj;
      simd::transpose(F4::load(s.vel_half[ja]), F4::load(s.vel_half[jb]), F4::load(s.vel_half[jc]),
                      F4::load(s.vel_half[jd]), dvx, dvy, dvz, mj);
      dvx -= vxi, dvy -= vyi, dvz -= vzi;
      const F4 neg_inv_dist = simd::neg_rsqrt(max(d2, tiny));
      const F4 neg_dist = d2 * neg_inv_dist;
      const F4 v_n_dist = dvx * dx + dvy * dy + dvz * dz;  // v_n |d|
      // sqrt(m_eff) = sqrt(mi mj / (mi + mj)) = mi mj / sqrt(mi mj (mi + mj)): one estimate, no reciprocal.
      const F4 mi_mj = mi * mj;
      const F4 c = neg_damping * mi_mj * simd::neg_rsqrt(mi_mj * (mi + mj));  // damping * sqrt(m_eff)
      // f / |d| multiplies the unnormalised d: the normal is never formed.
      const F4 f_over_dist = keep(touching, (k * (reach + neg_dist) + c * (v_n_dist * neg_inv_dist)) * neg_inv_dist);
      fx += f_over_dist * dx;
      fy += f_over_dist * dy;
      fz += f_over_dist * dz;
    }
    F4 fa, fb, fc, fd;
    simd::transpose(fx, fy, fz, F4::zero(), fa, fb, fc, fd);
    fa.store(forces[a - first]);
    fb.store(forces[b - first]);
    fc.store(forces[c - first]);
    fd.store(forces[d - first]);
  }
}

}  // namespace

const Kernels kSseKernels{
    "sse", "sse4.1", true, step<F4, pair_forces>, accelerations<F4, pair_forces>, build_lists_and_batch_order};

}  // namespace fishtank
