#pragma once
// Named benchmark scenes, each built and brought to rest the same way for
// every variant, so their timings compare like with like.
//
// The scenes themselves are server/scenes/scene_presets.h, shared with the
// interactive server.

#include <cstdint>

#include "server/realtime_loop.h"
#include "server/scenes/scene_presets.h"

namespace fishtank {

struct SettleReport {
  bool settled = false;
  double sim_seconds = 0.0;
  double wall_seconds = 0.0;
  std::uint64_t steps = 0;
};

// Steps until every ball is in and the pile is at rest (mean kinetic energy
// per ball below kRestEnergy at kRestChecks checks in a row, a tenth of a
// simulated second apart), or the time limit passes. Prints progress on stderr.
SettleReport settle(TunedStepper& stepper, const SceneSpec& spec);

// At rest, as LAMMPS runs usually take it. Not "every ball below some speed":
// a frictionless ball can slide along the floor for minutes.
inline constexpr double kRestEnergy = 1e-6;  // J per ball

// A soft pile can dip under kRestEnergy and swing back: rest is this many checks in a row.
inline constexpr int kRestChecks = 5;

// Counts the checks in a row that found the pile at rest.
struct RestWatch {
  int in_a_row = 0;
  bool settled(bool at_rest) {
    in_a_row = at_rest ? in_a_row + 1 : 0;
    return in_a_row >= kRestChecks;
  }
};

}  // namespace fishtank
