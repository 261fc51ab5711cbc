#pragma once
// How fast simulated time runs against the wall clock (LoopStatus::time_scale,
// Snapshot.time_scale), worded the same by the server's status line and the HUD.

namespace fishtank {

// Below this the world is said to run in slow motion; just under 1 is the
// ordinary jitter of a paced loop, not a shortfall worth reporting.
inline constexpr double kSlowMotionBelow = 0.98;

// A time scale of 0 (or less) means none was reported. asked is the time
// scale people set (RunControl::time_scale): only a shortfall against it is
// slow motion, a clock they slowed on purpose is not.
inline bool slow_motion(double time_scale, double asked = 1.0) {
  return time_scale > 0.0 && time_scale < kSlowMotionBelow * asked;
}

}  // namespace fishtank
