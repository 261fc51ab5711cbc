#pragma once
// Named benchmark scenes, each built and brought to rest the same way for
// every variant, so their timings compare like with like.
//
// The scenes themselves are server/scenes/scene_presets.h, shared with the
// interactive server.

#include <cstdint>

#include "server/scenes/scene_presets.h"

namespace fishtank {

struct SettleReport {
  bool settled = false;
  double sim_seconds = 0.0;
  double wall_seconds = 0.0;
  std::uint64_t steps = 0;
};

// Steps until every ball is in and the mean kinetic energy per ball is below
// kRestEnergy, or the time limit passes. Prints progress on stderr.
SettleReport settle(World& world, const SceneSpec& spec);

inline constexpr double kRestEnergy = 1e-3;  // J per ball: about 3 cm/s for a mass-2 ball

}  // namespace fishtank
