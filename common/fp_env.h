#pragma once
// Floating-point environment shared by both variants.
//
// A settled pile is full of tiny velocities and forces whose products fall
// into the denormal range, where x86 arithmetic is many times slower. Physics never
// needs values below 1e-38, so every thread that steps the world flushes
// denormals to zero (FTZ) and treats denormal inputs as zero (DAZ). This is a
// property of the thread's MXCSR register, used by scalar and SSE float code
// alike, so both twins run under the same rule and stay comparable.

namespace fishtank {

void enable_flush_denormals_to_zero();

}  // namespace fishtank
