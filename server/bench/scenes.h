#pragma once
// Named benchmark scenes, each built and brought to rest the same way for
// every variant, so their timings compare like with like.
//
//   tank  the product's 40-unit tank; N balls pour in from the top.
//   wide  the same height, widened so N balls dropped from a loose lattice
//         settle into a layer about a third of the height: cost per
//         ball-step should not grow with N.

#include <cstdint>
#include <memory>
#include <string>

#include "server/physics/world.h"

namespace fishtank {

struct SceneSpec {
  std::string name = "tank";
  std::uint32_t balls = 6000;
  std::uint64_t seed = 1;
  double max_settle_seconds = 0.0;  // simulated; 0 means the scene's default
};

struct SettleReport {
  bool settled = false;
  double sim_seconds = 0.0;
  double wall_seconds = 0.0;
  std::uint64_t steps = 0;
};

bool is_known_scene(const std::string& name);
// Tank bounds the scene needs for this many balls.
TankBounds scene_tank(const SceneSpec& spec);
// Puts the scene's balls in (queued or placed); returns a refusal message or "".
std::string populate(World& world, const SceneSpec& spec);
// Steps until every ball is in and the mean kinetic energy per ball is below
// kRestEnergy, or the time limit passes. Prints progress on stderr.
SettleReport settle(World& world, const SceneSpec& spec);

inline constexpr double kRestEnergy = 1e-3;  // J per ball: about 3 cm/s for a mass-2 ball

}  // namespace fishtank
