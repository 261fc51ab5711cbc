#pragma once
// The hot passes of a step (the step pass and the neighbour-list build), in
// twins with the same signatures:
//   kernels_scalar.cpp  plain C++, one pair at a time (the reference)
//   kernels_sse.cpp     SSE4.1, four balls and one neighbour of each at a time
//   kernels_avx2.cpp    AVX2 + FMA, eight balls at a time (a third level)
// The SIMD passes are written once for either vector (kernels_simd_ball.h).
//
// Velocity Verlet in one pass per step, double-buffered: the pass reads
// (pos, vel_half) of ball i and its neighbours and writes only ball i's
// outputs, so chunks run in parallel with no races and no atomics:
//   a    = F(pos, vel_half, vel_half_before) / m + g   (F: the mean force over the step, contact_law.h)
//   v    = vel_half + a dt/2                 (the full step, not stored)
//   vel_half_next = v + a dt/2,  pos_next = pos + vel_half_next dt
// vel_half_before, the half-step velocity a step earlier (the buffers rotate),
// gives the last step's acceleration, from which each contact takes the
// other forces on its pair (contact_law.h).

#include <cstdint>
#include <limits>

#include "common/float4.h"
#include "server/physics/broadphase.h"
#include "server/physics/params.h"

namespace fishtank {

// The arrays every twin's step reads and writes.
struct StepArrays {
  const Float4* pos = nullptr;  // x, y, z, radius at this step
  // vx, vy, vz, 1 / mass half a step before: F / m becomes a product, and a
  // pair's effective mass 1 / (1/m1 + 1/m2) one sum.
  const Float4* vel_half = nullptr;
  const Float4* vel_half_before = nullptr;  // vel_half a step earlier
  Float4* pos_next = nullptr;               // out: position one step later
  Float4* vel_half_next = nullptr;          // out: velocity half a step later
  StepLists lists;                     // full lists, each pair from both sides, in the twin's layout (broadphase.h)
  const Float4* player_pos = nullptr;  // x, y, z, radius
  const Float4* player_vel = nullptr;  // vx, vy, vz, 0: a kinematic body's inverse mass
  int players = 0;
  TankBounds tank;  // the walls: the world's tank, copied for the step
  // Balls whose pos_next lies further than sqrt(stray_d2) from where the
  // lists were built have strayed: chunk [begin, end) lists its own, each once, at
  // stray_balls + begin, for the world to check (World::lists_hold).
  float stray_d2 = std::numeric_limits<float>::infinity();
  std::uint32_t* stray_balls = nullptr;
};

// Rows [rows_begin, rows_end) of pos and vel_half, asked for while batches
// [first_batch, end_batch) run (numbered by ball / kStepBatch).
struct RowFetch {
  std::uint32_t rows_begin = 0, rows_end = 0;
  std::uint32_t first_batch = 0, end_batch = 0;
};

// What a SIMD step asks memory for ahead of use (kernels_simd_prefetch.h). Results
// never depend on it; the scalar twin reads its rows in order and takes none.
struct PrefetchPlan {
  bool beyond_cache = false;                // ask for rows kPrefetchBatches ahead, and the remote rows
  const RemoteRows* remote_rows = nullptr;  // per batch, `batches` of them
  std::uint32_t balls = 0, batches = 0;     // n, and n / kStepBatch rounded up
  const BatchReach* reach = nullptr;        // per batch, the rows its lists read: each chunk's EdgeFetches
};

// What one chunk of a SIMD step asks for ahead besides the PrefetchPlan (prefetch_plan.h).
struct EdgeFetches {
  RowFetch rows[2] = {};                       // rows that the neighbouring chunks' threads write or read too
  std::uint32_t lead_begin = 0, lead_end = 0;  // batches run first, while rows[0] arrives
};

// Everything a step pass reads, built once per step by the world (World::step) and
// passed whole through every layer of the kernels, as Box2D's b2StepContext is.
struct StepContext {
  StepArrays arrays;
  PrefetchPlan plan;
  ContactModel model;
};

// How far the balls of a chunk moved from where the lists were built.
struct Moved {
  float max_d2 = 0.0f;        // the largest squared distance of pos_next from the build's position
  float max_v2 = 0.0f;        // the largest squared speed in vel_half_next: the next step's lead (ContactModel)
  std::uint32_t strayed = 0;  // balls beyond StepArrays::stray_d2, listed at stray_balls + begin
};

struct Kernels {
  const char* variant;       // "scalar", "sse" or "avx2"
  const char* simd;          // instruction set of the kernels
  bool threaded;             // whether the build may use more than one thread
  std::uint32_t list_lanes;  // balls per group in the lists' layout (broadphase.h)
  // Each pass takes balls [begin, end) from batch edges (kStepBatch): the lists are laid out per batch.
  // The step returns how far the balls moved since the build, which says when to rebuild.
  Moved (*step)(const StepContext& ctx, std::uint32_t begin, std::uint32_t end);
  // a = F(pos, vel_half) / m + g only, into acc: for balls placed in contact, whose forces are not known yet.
  void (*accelerations)(const StepContext& ctx, Float4* acc, std::uint32_t begin, std::uint32_t end);
  // Neighbour lists (see broadphase.h). Returns the longest.
  std::uint32_t (*build_lists)(const ListBuild& b, std::uint32_t begin, std::uint32_t end);
};

// One ball's half kick from full-step velocity v (w: 1 / mass) and drift from p; returns the squared
// distance of pos_next from at_build. The scalar step and the world's spawned or placed balls share it.
inline float kick_drift(const ContactModel& m, const Float4& v, const Float4& p, const Float4& a,
                        const Float4& at_build, Float4& vel_half_next, Float4& pos_next) {
  const Float4 vh{v.x + a.x * m.half_dt, v.y + a.y * m.half_dt, v.z + a.z * m.half_dt, v.w};
  const Float4 next{p.x + vh.x * m.dt, p.y + vh.y * m.dt, p.z + vh.z * m.dt, p.w};
  vel_half_next = vh;
  pos_next = next;
  const float dx = next.x - at_build.x, dy = next.y - at_build.y, dz = next.z - at_build.z;
  return dx * dx + dy * dy + dz * dz;
}

extern const Kernels kScalarKernels;
extern const Kernels kSseKernels;
extern const Kernels kAvx2Kernels;  // run only where cpu_has_avx2()

inline bool cpu_has_avx2() { return __builtin_cpu_supports("avx2"); }

}  // namespace fishtank
