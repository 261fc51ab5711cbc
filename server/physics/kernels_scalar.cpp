// Scalar twin of the step kernels: the readable reference. See kernels.h.

#include <algorithm>
#include <cmath>
#include <vector>

#include "server/physics/contact_law.h"
#include "server/physics/kernels.h"

namespace fishtank {
namespace {

// Walls are half-spaces: the force keeps growing however deep the ball is.
// A wall is kinematic, so the pair's inverse mass is the ball's.
// before: the ball's velocity along the axis a step earlier.
inline float wall_force_1d(const ContactModel& m, float pos, float vel, float before, float r, float inv_mass, float c,
                           float lo, float hi) {
  float f = 0.0f;
  const float below = lo + r - pos, above = pos + r - hi;
  if (may_touch(m, below, vel)) f += normal_force(m, below, vel, c, inv_mass, before);
  if (may_touch(m, above, -vel)) f -= normal_force(m, above, -vel, c, inv_mass, -before);
  return f;
}

// A body's position, half-step velocity and that velocity a step earlier (StepArrays).
struct Body {
  Float4 pos, vel, before;
};

// The contact force on ball i from body j (a ball, or a player sphere with
// inverse mass 0), zero unless they touch within half a step. d points from i
// to j, and v_n is the rate at which the gap opens; the force pushes i back along -d.
inline Float4 contact_force(const ContactModel& m, const Body& i, const Body& j) {
  const Float4 &pi = i.pos, &vi = i.vel, &pj = j.pos, &vj = j.vel;
  const float dx = pj.x - pi.x, dy = pj.y - pi.y, dz = pj.z - pi.z;
  const float d2 = dx * dx + dy * dy + dz * dz;
  const float reach = pi.w + pj.w, reach_lead = reach + m.lead_bound;
  if (!(d2 < reach_lead * reach_lead)) return Float4{};
  const float dist = std::max(std::sqrt(d2), 1e-6f);
  const float inv_dist = 1.0f / dist;
  const float nx = dx * inv_dist, ny = dy * inv_dist, nz = dz * inv_dist;
  const float v_n = (vj.x - vi.x) * nx + (vj.y - vi.y) * ny + (vj.z - vi.z) * nz;
  const Float4 &bi = i.before, &bj = j.before;
  const float v_n_before = (bj.x - bi.x) * nx + (bj.y - bi.y) * ny + (bj.z - bi.z) * nz;
  const float inv_m_sum = vi.w + vj.w;
  const float f = normal_force(m, reach - dist, v_n, contact_damping(m, inv_m_sum), inv_m_sum, v_n_before);
  return Float4{-f * nx, -f * ny, -f * nz, 0.0f};
}

// The sum of the contact forces of ball i's neighbours, in list order.
[[gnu::always_inline]] inline Float4 neighbour_forces(const StepContext& ctx, const BallLists& lists, std::uint32_t i,
                                                      const std::uint32_t* list) {
  const StepArrays& s = ctx.arrays;
  const ContactModel& m = ctx.model;
  const Body bi{s.pos[i], s.vel_half[i], s.vel_half_before[i]};
  float fx = 0.0f, fy = 0.0f, fz = 0.0f;
  for (std::uint32_t n = 0; n < lists.counts[i]; ++n) {
    const Body bj{listed(s.pos, list[n]), listed(s.vel_half, list[n]), listed(s.vel_half_before, list[n])};
    const Float4 f = contact_force(m, bi, bj);
    fx += f.x;
    fy += f.y;
    fz += f.z;
  }
  return Float4{fx, fy, fz, 0.0f};
}

// a = F / m + g for ball i: its neighbours' forces f, plus player spheres and walls.
[[gnu::always_inline]] inline Float4 acceleration(const StepContext& ctx, std::uint32_t i, const Float4& f) {
  const StepArrays& s = ctx.arrays;
  const ContactModel& m = ctx.model;
  const Body bi{s.pos[i], s.vel_half[i], s.vel_half_before[i]};
  const Float4 &pi = bi.pos, &vi = bi.vel, &before = bi.before;
  float fx = f.x, fy = f.y, fz = f.z;
  for (int p = 0; p < s.players; ++p) {
    const Float4& vp = s.player_vel[p];  // kinematic: taken as unaccelerated
    const Float4 fp = contact_force(m, bi, Body{s.player_pos[p], vp, vp});
    fx += fp.x;
    fy += fp.y;
    fz += fp.z;
  }
  const float c = contact_damping(m, vi.w);  // walls are kinematic: m_eff = m
  fx += wall_force_1d(m, pi.x, vi.x, before.x, pi.w, vi.w, c, s.tank.min.x, s.tank.max.x);
  fy += wall_force_1d(m, pi.y, vi.y, before.y, pi.w, vi.w, c, s.tank.min.y, s.tank.max.y);
  fz += wall_force_1d(m, pi.z, vi.z, before.z, pi.w, vi.w, c, s.tank.min.z, s.tank.max.z);
  return Float4{fx * vi.w, fy * vi.w - m.gravity, fz * vi.w, 0.0f};
}

// One pair at a time reads its rows in order: the prefetch plan is the SIMD twins'.
Moved step(const StepContext& context, std::uint32_t begin, std::uint32_t end) {
  // Local copies: stores through the output pointers cannot change them, so
  // pointers and constants stay in registers.
  const StepContext ctx = context;
  const StepArrays& s = ctx.arrays;
  const BallLists lists = std::get<BallLists>(s.lists);
  const ContactModel& m = ctx.model;
  Moved moved;
  // A batch's neighbour sums first, then the rest per ball: one loop doing
  // both keeps the wall and integration values live across the neighbour loop.
  Float4 pair_force[kStepBatch];
  for (std::uint32_t batch = begin, last_of_batch; batch < end; batch = last_of_batch) {
    last_of_batch = batch_end(batch, end);
    const std::uint32_t* list = lists.neighbours + std::size_t(batch) * lists.stride;
    for (std::uint32_t i = batch; i < last_of_batch; list += lists.counts[i++])
      pair_force[i - batch] = neighbour_forces(ctx, lists, i, list);
    for (std::uint32_t i = batch; i < last_of_batch; ++i) {
      const Float4 a = acceleration(ctx, i, pair_force[i - batch]);
      const Float4 vh = s.vel_half[i];
      const Float4 v{vh.x + a.x * m.half_dt, vh.y + a.y * m.half_dt, vh.z + a.z * m.half_dt, vh.w};
      const float d2 = kick_drift(m, v, s.pos[i], a, lists.at_build[i], s.vel_half_next[i], s.pos_next[i]);
      moved.max_d2 = std::max(moved.max_d2, d2);
      moved.max_v2 = std::max(moved.max_v2, squared_length3(s.vel_half_next[i]));
      if (d2 > s.stray_d2) s.stray_balls[begin + moved.strayed++] = i;
    }
  }
  return moved;
}

void accelerations(const StepContext& ctx, Float4* acc, std::uint32_t begin, std::uint32_t end) {
  const BallLists& lists = std::get<BallLists>(ctx.arrays.lists);
  for (std::uint32_t batch = begin; batch < end; batch += kStepBatch) {
    const std::uint32_t* list = lists.neighbours + std::size_t(batch) * lists.stride;
    for (std::uint32_t i = batch; i < batch_end(batch, end); list += lists.counts[i++])
      acc[i] = acceleration(ctx, i, neighbour_forces(ctx, lists, i, list));
  }
}

// Ball i's count entries, as found with their keys d^2 - (r_i + r_j)^2, into
// list nearest first, ties in the order found. The key is negative exactly
// while the pair touches and grows with the gap between the surfaces. Every
// twin's build orders its lists so (kernels_simd_lists.h has the SIMD one),
// and each ball sums its forces in the same order in all of them; a SIMD step
// skips the force of a block in which no lane touches, and in this order such
// blocks are a group's last, holding pairs only the skin keeps. Each entry's
// place is the number of entries before it in the order.
void order_nearest_first(const float* keys, const std::uint32_t* found, std::uint32_t count, std::uint32_t* list) {
  for (std::uint32_t k = 0; k < count; ++k) {
    std::uint32_t place = 0;
    for (std::uint32_t m = 0; m < count; ++m) place += keys[m] < keys[k] || (keys[m] == keys[k] && m < k);
    list[place] = list_entry(found[k]);
  }
}

// One lane: each batch's lists one after the other, in ball order (broadphase.h).
std::uint32_t build_lists(const ListBuild& b, std::uint32_t begin, std::uint32_t end) {
  thread_local std::vector<std::uint32_t> found;
  thread_local std::vector<float> keys;
  found.resize(b.stride);
  keys.resize(b.stride);
  std::uint32_t longest = 0;
  std::uint32_t* list = nullptr;
  for (std::uint32_t i = begin; i < end; ++i) {
    if (i % kStepBatch == 0) list = b.neighbours + std::size_t(i) * b.stride;
    b.batch_order[i] = i;
    const Float4 pi = b.pos[i];
    std::uint32_t count = 0;
    for_each_neighbour_range(b, i, [&](std::uint32_t j_begin, std::uint32_t j_end) {
      for (std::uint32_t j = j_begin; j < j_end; ++j) {
        const Float4& pj = b.pos[j];
        const float dx = pi.x - pj.x, dy = pi.y - pj.y, dz = pi.z - pj.z;
        const float d2 = dx * dx + dy * dy + dz * dz, reach = pi.w + pj.w, cutoff = reach + b.skin;
        if (!(d2 < cutoff * cutoff) || j == i) continue;  // a NaN is no neighbour, as in the SIMD builds
        if (count < b.stride) found[count] = j, keys[count] = d2 - reach * reach;
        ++count;
      }
    });
    b.counts[i] = count;
    const std::uint32_t stored = std::min(count, b.stride);
    order_nearest_first(keys.data(), found.data(), stored, list);
    list += stored;
    longest = std::max(longest, count);
  }
  return longest;
}

}  // namespace

const Kernels kScalarKernels{"scalar", "none", false, 1, step, accelerations, build_lists};

}  // namespace fishtank
