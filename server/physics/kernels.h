#pragma once
// The two hot passes of a step, each in two twins with the same signature:
//   kernels_scalar.cpp  plain C++, one pair at a time (the reference)
//   kernels_sse.cpp     SSE4.1, four neighbours at a time
//   kernels_avx2.cpp    AVX2 + FMA, eight neighbours at a time (a third level)
// The two SIMD files share their per-ball code (kernels_simd_ball.h).
// A build picks one set at compile time (see server/main.cpp); the tests hold
// them all so they can compare them.
//
// Velocity Verlet, split so each pass writes only ball i and reads neighbours
// only from arrays the pass does not write (no races, no atomics):
//   kick_drift:   v_half = v + a dt/2;  x += v_half dt
//   forces_kick:  a = F(x, v_half) / m + g;  v = v_half + a dt/2

#include <cstdint>

#include "common/float4.h"
#include "server/physics/params.h"

namespace fishtank {

struct StepArrays {
  Float4* pos;       // x, y, z, radius
  Float4* vel;       // vx, vy, vz, mass (velocity at the full step)
  Float4* vel_half;  // vx, vy, vz, mass (velocity at the half step)
  Float4* acc;       // ax, ay, az, 0
  const Float4* pos_at_build;
  // Full neighbour list (each pair appears from both sides): ball i's
  // neighbours are neighbours[i * stride, i * stride + count[i]), followed by
  // ghost indices up to a multiple of kListPadding so SIMD loads need no tail loop.
  const std::uint32_t* neighbours;
  const std::uint32_t* neighbour_count;
  std::uint32_t stride;
  const Float4* player_pos;  // x, y, z, radius
  const Float4* player_vel;  // vx, vy, vz, 0
  int players;
};

struct Kernels {
  const char* variant;  // "scalar" or "sse"
  const char* simd;     // instruction set of the kernels
  int lanes;            // neighbours per SIMD block (1 for scalar)
  bool threaded;        // whether the build may use more than one thread
  // Returns the largest squared displacement since the neighbour list was built.
  float (*kick_drift)(const StepArrays& s, const ContactModel& m, std::uint32_t begin, std::uint32_t end);
  void (*forces_kick)(const StepArrays& s, const ContactModel& m, std::uint32_t begin, std::uint32_t end);
};

extern const Kernels kScalarKernels;
extern const Kernels kSseKernels;
extern const Kernels kAvx2Kernels;  // run only where cpu_has_avx2()

inline bool cpu_has_avx2() { return __builtin_cpu_supports("avx2"); }

// Lists are padded for the widest kernel; a narrower one reads a shorter prefix.
constexpr std::uint32_t kListPadding = 8;
inline std::uint32_t padded_neighbour_count(std::uint32_t count, std::uint32_t lanes) {
  return (count + lanes - 1) / lanes * lanes;
}

}  // namespace fishtank
