#pragma once
// The contact law, once per twin: the scalar function first, the SIMD one
// (any vector type V of common/simd) below it, the same arithmetic in the same
// order. Every contact uses it: ball pairs, walls and player spheres.
//
// A step kicks each velocity by the force's impulse over the window
// [t - dt/2, t + dt/2] around the positions' time t. Evaluating k x at t alone
// (as LAMMPS does) is right while the pair overlaps for the whole window, but
// a contact that starts or ends inside it gets an impulse that depends on where
// in the step that happens: one collision's e then scatters by +-0.03 at 20
// steps per contact. Here the overlap moves linearly across the window,
//
//        overlap                       lead = |v_n| dt/2
//          ^          ____/            in_contact f = clamp((x + lead) / (2 lead), 0, 1)
//          |     ___/ |                mean overlap = x                     (f = 1)
//     0 ---+---/------+---> t                       = (x + lead) f / 2      (f < 1)
//          t-dt/2  t  t+dt/2
//
// and the spring's impulse is k times the overlap's integral over the part of
// the window in contact (a triangle where it starts or ends, x itself where it
// lasts). Where it starts or ends, the lead is taken once more from the rate at
// mid-window, after the half kick of the spring and of the pair's other forces
// (other contacts, gravity): start and end then mirror each other, and an
// elastic contact neither gains nor loses energy on average, alone or in a
// group of touching balls.
// The dashpot acts over that part, f dt, on the pair's rate at t: the rate
// v_n at t - dt/2 plus half a step of the spring, of the pair's other forces
// and of the dashpot itself, solved implicitly for this contact:
//   F = k mean_overlap - c f / (1 + beta) (v_n + (k mean_overlap / m_eff + other) dt / 2),
//   beta = c f dt / (2 m_eff).
// Without the other forces a dashpot in a row of touching balls acts on the
// wrong rate by O(dt) and the row's collisions are first order; with them,
// second order. A ball at rest rests on k x: there the spring and the other
// forces cancel.
// The other forces (other contacts, gravity) are the pair's relative
// acceleration over the last step less this contact's own force then, which the
// law recomputes from the overlap and rate of a step before, its dashpot acting
// on the same other forces (other_forces).
//
// x is the overlap (negative: the gap), v_n the rate at which the gap opens,
// inv_m_sum the pair's 1 / m_eff (a wall or a player adds 0), v_before the
// rate a step earlier (from StepArrays::vel_half_before): (v_n - v_before) / dt
// is the pair's relative acceleration over the last step.

#include <algorithm>
#include <cmath>

#include "server/physics/params.h"

namespace fishtank {

// 2 lead below this is no lead: a pair at rest has none, and the fraction then only says touching or not.
constexpr float kSmallestLead = 1e-20f;

// c for a pair of inverse-mass sum inv_m_sum.
inline float contact_damping(const ContactModel& m, float inv_m_sum) { return m.damping_factor / std::sqrt(inv_m_sum); }

// c / (1 + beta) for a contact over the fraction of the step in which c_f = c f acts.
inline float whole_step_damping(const ContactModel& m, float c_f, float inv_m_sum) {
  return c_f / (1.0f + c_f * m.half_dt * inv_m_sum);
}

// Whether the overlap x reaches 0 within half a step (otherwise the law gives 0).
inline bool may_touch(const ContactModel& m, float overlap, float v_n) {
  return overlap + std::fabs(v_n) * m.half_dt > 0.0f;
}

// The fraction of the window in contact and the overlap's mean over the window, for a lead.
struct WindowContact {
  float fraction, mean_overlap;
};

inline WindowContact window_contact(float overlap, float lead) {
  if (overlap > lead) return {1.0f, overlap};  // the whole window, as below, without a divide
  const float reach_in = overlap + lead;
  const float fraction = std::clamp(reach_in / std::max(lead + lead, kSmallestLead), 0.0f, 1.0f);
  return {fraction, fraction < 1.0f ? 0.5f * reach_in * fraction : overlap};
}

// The window where a contact starts or ends, from the pair's rate v_n and its other forces' acceleration.
inline WindowContact partial_window(const ContactModel& m, float overlap, float v_n, float inv_m_sum, float other) {
  const WindowContact part = window_contact(overlap, std::fabs(v_n + other * m.half_dt) * m.half_dt);
  const float v_mid = v_n + (m.k * part.mean_overlap * inv_m_sum + other) * m.half_dt;  // after the half kick
  return window_contact(overlap, std::fabs(v_mid) * m.half_dt);
}

// The window a step before, as for a pair alone (the other forces' share of its lead left out).
inline WindowContact window_before(const ContactModel& m, float then, float v_before, float inv_m_sum) {
  const WindowContact part = window_contact(then, std::fabs(v_before) * m.half_dt);
  return part.fraction > 0.0f && part.fraction < 1.0f ? partial_window(m, then, v_before, inv_m_sum, 0.0f) : part;
}

// The other forces on the pair: a step before, at overlap then = x + v_n dt (the drift undone) and rate
// v_before, the pair's acceleration (v_n - v_before) / dt was this law over that window, times 1 / m_eff,
// plus the other forces, the dashpot acting on them too. Solved for them, with c_f = c f then,
//   other = (1 + c_f dt / (2 m_eff)) a_rel - (k mean_overlap - c_f v_before) / m_eff.
inline float other_forces(const ContactModel& m, WindowContact then, float v_n, float c, float inv_m_sum,
                          float v_before) {
  const float c_f = c * then.fraction;
  const float a_rel = (v_n - v_before) * (1.0f / m.dt);
  return (1.0f + c_f * m.half_dt * inv_m_sum) * a_rel - (m.k * then.mean_overlap - c_f * v_before) * inv_m_sum;
}

inline float normal_force(const ContactModel& m, float overlap, float v_n, float c, float inv_m_sum, float v_before) {
  WindowContact part = window_contact(overlap, std::fabs(v_n) * m.half_dt);
  if (part.fraction <= 0.0f) return 0.0f;
  const WindowContact then = window_before(m, overlap + v_n * m.dt, v_before, inv_m_sum);
  const float other = other_forces(m, then, v_n, c, inv_m_sum, v_before);
  if (part.fraction < 1.0f) part = partial_window(m, overlap, v_n, inv_m_sum, other);
  const float spring = m.k * part.mean_overlap, pushed = spring * inv_m_sum + other;
  return spring - whole_step_damping(m, c * part.fraction, inv_m_sum) * (v_n + pushed * m.half_dt);
}

// Where a contact lasts the whole window now and lasted it a step before, normal_force's arithmetic
// gathers into F = k x - now v_n - before v_before, the other forces included: with beta = c dt / (2 m_eff)
// and D = c / (1 + beta), now = D (3 + beta - k dt^2 / m_eff) / 2 and before = D (beta - 1) / 2.
// The SIMD twin's fast path takes that form.
struct WholeWindowDamping {
  float now, before;
};

inline WholeWindowDamping whole_window_damping(const ContactModel& m, float c, float inv_m_sum) {
  const float beta = c * m.half_dt * inv_m_sum, damping = whole_step_damping(m, c, inv_m_sum);
  return {0.5f * damping * (3.0f + beta - m.k * inv_m_sum * m.dt * m.dt), 0.5f * damping * (beta - 1.0f)};
}

namespace {  // compiled with each SIMD file's flags: internal linkage (kernels_simd_ball.h)

template <class V>
[[gnu::always_inline]] inline V whole_step_damping(const ContactModel& m, V c_f, V inv_m_sum) {
  return c_f / (V::splat(1.0f) + c_f * V::splat(m.half_dt) * inv_m_sum);
}

// A pair's c and its whole_window_damping.
template <class V>
struct WholeDashpot {
  V c, now, before;
};

template <class V>
struct WindowContactV {
  V fraction, mean_overlap;
};

template <class V>
[[gnu::always_inline]] inline WindowContactV<V> window_contact(V overlap, V lead) {
  const V one = V::splat(1.0f);
  const V reach_in = overlap + lead;
  const V fraction = min(max(reach_in / max(lead + lead, V::splat(kSmallestLead)), V::zero()), one);
  return {fraction, select(fraction < one, V::splat(0.5f) * reach_in * fraction, overlap)};
}

template <class V>
[[gnu::always_inline]] inline WindowContactV<V> partial_window(const ContactModel& m, V overlap, V v_n, V inv_m_sum,
                                                               V other) {
  const V half_dt = V::splat(m.half_dt);
  const WindowContactV<V> part = window_contact(overlap, abs(v_n + other * half_dt) * half_dt);
  const V v_mid = v_n + (V::splat(m.k) * part.mean_overlap * inv_m_sum + other) * half_dt;  // after the half kick
  return window_contact(overlap, abs(v_mid) * half_dt);
}

// Lanes where the window holds part of the contact.
template <class V>
[[gnu::always_inline]] inline auto is_partial(const WindowContactV<V>& part) {
  return (part.fraction > V::zero()) & (part.fraction < V::splat(1.0f));
}

template <class V>
[[gnu::always_inline]] inline WindowContactV<V> select(decltype(V::zero() < V::zero()) lanes,
                                                       const WindowContactV<V>& a, const WindowContactV<V>& b) {
  return {select(lanes, a.fraction, b.fraction), select(lanes, a.mean_overlap, b.mean_overlap)};
}

template <class V>
[[gnu::always_inline]] inline WindowContactV<V> window_before(const ContactModel& m, V then, V v_before, V inv_m_sum) {
  const WindowContactV<V> part = window_contact(then, abs(v_before) * V::splat(m.half_dt));
  if (!any(is_partial(part))) return part;  // mostly: the contact started or ended a step before in few lanes
  return select<V>(is_partial(part), partial_window(m, then, v_before, inv_m_sum, V::zero()), part);
}

template <class V>
[[gnu::always_inline]] inline V other_forces(const ContactModel& m, WindowContactV<V> then, V v_n, V c, V inv_m_sum,
                                             V v_before) {
  const V c_f = c * then.fraction;
  const V a_rel = (v_n - v_before) * V::splat(1.0f / m.dt);
  return (V::splat(1.0f) + c_f * V::splat(m.half_dt) * inv_m_sum) * a_rel -
         (V::splat(m.k) * then.mean_overlap - c_f * v_before) * inv_m_sum;
}

// Lanes that start or end touching within half a step: every other lane
// touches all step (overlap >= lead) or not at all.
template <class V>
[[gnu::always_inline]] inline auto starting_or_ending(const ContactModel& m, V overlap, V v_n) {
  return abs(overlap) < abs(v_n) * V::splat(m.half_dt);
}

// Lanes whose force needs normal_force: their contact starts or ends this step, or touches all step and
// did not a step before.
template <class V>
[[gnu::always_inline]] inline auto needs_whole_law(const ContactModel& m, V overlap, V v_n, V v_before) {
  const V then = overlap + v_n * V::splat(m.dt);
  return starting_or_ending(m, overlap, v_n) | ((overlap > V::zero()) & (then < abs(v_before) * V::splat(m.half_dt)));
}

// The law where no lane needs_whole_law: each touches all step, now and a step before, or not at all
// (whole_window_damping).
template <class V>
[[gnu::always_inline]] inline V whole_or_no_contact_force(const ContactModel& m, V overlap, V v_n, V v_before,
                                                          const WholeDashpot<V>& d) {
  return keep(overlap > V::zero(), V::splat(m.k) * overlap - d.now * v_n - d.before * v_before);
}

template <class V>
[[gnu::always_inline]] inline V normal_force(const ContactModel& m, V overlap, V v_n, V c, V inv_m_sum, V v_before) {
  const WindowContactV<V> then = window_before(m, overlap + v_n * V::splat(m.dt), v_before, inv_m_sum);
  const V other = other_forces(m, then, v_n, c, inv_m_sum, v_before);
  WindowContactV<V> part = window_contact(overlap, abs(v_n) * V::splat(m.half_dt));
  part = select<V>(is_partial(part), partial_window(m, overlap, v_n, inv_m_sum, other), part);
  const V spring = V::splat(m.k) * part.mean_overlap, pushed = spring * inv_m_sum + other;
  return spring - whole_step_damping(m, c * part.fraction, inv_m_sum) * (v_n + pushed * V::splat(m.half_dt));
}

}  // namespace
}  // namespace fishtank
