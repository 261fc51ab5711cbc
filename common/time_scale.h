#pragma once
// How fast simulated time runs against the wall clock (LoopStatus::time_scale,
// Snapshot.time_scale), worded the same by the server's status line and the HUD.

namespace fishtank {

// Below this the world is said to run in slow motion; just under 1 is the
// ordinary jitter of a paced loop, not a shortfall worth reporting.
inline constexpr double kSlowMotionBelow = 0.98;

// A time scale of 0 (or less) means none was reported.
inline bool slow_motion(double time_scale) { return time_scale > 0.0 && time_scale < kSlowMotionBelow; }

}  // namespace fishtank
