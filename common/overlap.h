#pragma once
// How deep balls may sink into each other before the server and the HUD warn
// (overlap_warning in world_measures.h, Snapshot.max_overlap): beyond it they visibly do,
// and the stiffness is too soft for the load.

namespace fishtank {

// The largest overlap, as a fraction of the smaller radius, accepted without a warning.
inline constexpr float kOverlapWarning = 0.10f;

inline bool overlap_too_deep(float fraction) { return fraction > kOverlapWarning; }

}  // namespace fishtank
