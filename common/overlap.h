#pragma once
// How deep balls may sink into each other before the server and the HUD warn
// (overlap_warning in world_measures.h, Snapshot.max_overlap): beyond it, once the balls
// rest, they visibly do and the stiffness is too soft for the load. While they still fly
// in, the deepest overlap is an impact's (v sqrt(m / k): 35 % at 28 m/s), not the load's.

namespace fishtank {

// The largest overlap, as a fraction of the smaller radius, accepted without a warning.
inline constexpr float kOverlapWarning = 0.10f;

// Mean kinetic energy per ball (J) below which the balls count as resting: a unit ball at 0.1 m/s.
inline constexpr double kRestingEnergyPerBall = 5e-3;

// Whether an overlap of this fraction, with the balls' mean kinetic energy per ball, says k is too soft.
inline bool resting_overlap_too_deep(float fraction, double energy_per_ball) {
  return fraction > kOverlapWarning && energy_per_ball <= kRestingEnergyPerBall;
}

}  // namespace fishtank
