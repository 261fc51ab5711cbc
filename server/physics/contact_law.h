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
// group of touching balls. The other forces are the pair's relative acceleration
// over the last step less this contact's own then, which the law recomputes from
// the overlap and rate of a step before.
// The dashpot acts over that part, f dt, on the relative speed solved
// implicitly for this contact alone: beta = c f dt / (2 m_eff) and
//   F = k mean_overlap - c f / (1 + beta) v_n.
// The implicit factor touches the dashpot only, so a resting contact (v_n = 0)
// rests on k x. That is the pair's trapezoid rule on a spring k (1 + beta),
// whose damping ratio is lower by sqrt(1 + beta); c is raised by the same
// factor to first order, c + c^2 dt / (4 m_eff) = c + damping_factor^2 dt / 4,
// which leaves each collision's restitution second order in dt.
//
// x is the overlap (negative: the gap), v_n the rate at which the gap opens,
// inv_m_sum the pair's 1 / m_eff (a wall or a player adds 0), v_before the
// rate a step earlier (from StepArrays::vel_half_before; the scalar law asks
// for it only where a contact starts or ends): (v_n - v_before) / dt is the
// pair's relative acceleration over the last step.

#include <algorithm>
#include <cmath>

#include "server/physics/params.h"

namespace fishtank {

// 2 lead below this is no lead: a pair at rest has none, and the fraction then only says touching or not.
constexpr float kSmallestLead = 1e-20f;

// c for a pair of inverse-mass sum inv_m_sum, raised as the header says.
inline float contact_damping(const ContactModel& m, float inv_m_sum) {
  return m.damping_factor / std::sqrt(inv_m_sum) + m.damping_boost;
}

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

inline float law_in_window(const ContactModel& m, WindowContact part, float v_n, float c, float inv_m_sum) {
  return m.k * part.mean_overlap - whole_step_damping(m, c * part.fraction, inv_m_sum) * v_n;
}

// The law for a pair alone (no other forces): this contact's own force a step before.
inline float lone_pair_force(const ContactModel& m, float overlap, float v_n, float c, float inv_m_sum) {
  WindowContact part = window_contact(overlap, std::fabs(v_n) * m.half_dt);
  if (part.fraction > 0.0f && part.fraction < 1.0f) part = partial_window(m, overlap, v_n, inv_m_sum, 0.0f);
  return law_in_window(m, part, v_n, c, inv_m_sum);
}

template <class RateBefore>
inline float normal_force(const ContactModel& m, float overlap, float v_n, float c, float inv_m_sum,
                          RateBefore v_before) {
  WindowContact part = window_contact(overlap, std::fabs(v_n) * m.half_dt);
  if (part.fraction > 0.0f && part.fraction < 1.0f) {
    // A step before, the overlap was x + v_n dt (the drift undone) and the rate v_before.
    const float then = overlap + v_n * m.dt, v_then = v_before();
    const float own = may_touch(m, then, v_then) ? lone_pair_force(m, then, v_then, c, inv_m_sum) * inv_m_sum : 0.0f;
    part = partial_window(m, overlap, v_n, inv_m_sum, (v_n - v_then) * (1.0f / m.dt) - own);
  }
  return law_in_window(m, part, v_n, c, inv_m_sum);
}

namespace {  // compiled with each SIMD file's flags: internal linkage (kernels_simd_ball.h)

template <class V>
[[gnu::always_inline]] inline V contact_damping(const ContactModel& m, V inv_m_sum) {
  return V::splat(m.damping_factor) / sqrt(inv_m_sum) + V::splat(m.damping_boost);
}

template <class V>
[[gnu::always_inline]] inline V whole_step_damping(const ContactModel& m, V c_f, V inv_m_sum) {
  return c_f / (V::splat(1.0f) + c_f * V::splat(m.half_dt) * inv_m_sum);
}

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

template <class V>
[[gnu::always_inline]] inline V law_in_window(const ContactModel& m, WindowContactV<V> part, V v_n, V c, V inv_m_sum) {
  return V::splat(m.k) * part.mean_overlap - whole_step_damping(m, c * part.fraction, inv_m_sum) * v_n;
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

// Lanes that start or end touching within half a step, whose force needs the
// whole law; every other lane touches all step (overlap >= lead) or not at all.
template <class V>
[[gnu::always_inline]] inline auto starting_or_ending(const ContactModel& m, V overlap, V v_n) {
  return abs(overlap) < abs(v_n) * V::splat(m.half_dt);
}

// Where every lane touches all step or not at all, the law with in_contact 1 or 0:
// damping is whole_step_damping(c) of each lane's pair.
template <class V>
[[gnu::always_inline]] inline V whole_or_no_contact_force(const ContactModel& m, V overlap, V v_n, V damping) {
  return keep(overlap > V::zero(), V::splat(m.k) * overlap - damping * v_n);
}

// damping: whole_step_damping(c), the pair's damping where its contact lasts the whole window.
template <class V>
[[gnu::always_inline]] inline V lone_pair_force(const ContactModel& m, V overlap, V v_n, V c, V inv_m_sum, V damping) {
  if (any(starting_or_ending(m, overlap, v_n))) {  // rare: the last step's contact started or ended too
    const WindowContactV<V> part = window_contact(overlap, abs(v_n) * V::splat(m.half_dt));
    const WindowContactV<V> mid = partial_window(m, overlap, v_n, inv_m_sum, V::zero());
    return law_in_window(m, select<V>(is_partial(part), mid, part), v_n, c, inv_m_sum);
  }
  return whole_or_no_contact_force(m, overlap, v_n, damping);
}

template <class V>
[[gnu::always_inline]] inline V normal_force(const ContactModel& m, V overlap, V v_n, V c, V inv_m_sum, V v_before) {
  const V damping = whole_step_damping(m, c, inv_m_sum);
  const V then = overlap + v_n * V::splat(m.dt);
  const V own =
      lone_pair_force(m, then, v_before, c, inv_m_sum, damping) * inv_m_sum;  // 0 where the pair did not touch
  const WindowContactV<V> mid =
      partial_window(m, overlap, v_n, inv_m_sum, (v_n - v_before) * V::splat(1.0f / m.dt) - own);
  return select(starting_or_ending(m, overlap, v_n), law_in_window(m, mid, v_n, c, inv_m_sum),
                whole_or_no_contact_force(m, overlap, v_n, damping));
}

}  // namespace
}  // namespace fishtank
