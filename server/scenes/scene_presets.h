#pragma once
// The named scenes, shared by the benchmark (--bench --scene) and the
// interactive server (--scene, and live switches from clients).
//
//   tank       the product's 40-unit tank; balls pour in from the top (SPEC 1.2).
//   wide       the same height, widened so the balls, dropped from a loose
//              lattice, settle into a layer about a third of the height.
//   dam-break  a column of small balls against the -x wall of the tank, released.
//   drop       large balls fall from near the top onto a bed of small ones.
//
// A scene is a tank and a way to fill it; starting one again with the same
// seed gives the same start.

#include <cstdint>
#include <string>

#include "server/physics/world.h"

namespace fishtank {

struct SceneSpec {
  std::string name = "tank";
  std::uint32_t balls = 6000;
  std::uint64_t seed = 1;
  double max_settle_seconds = 0.0;  // simulated; 0 means the scene's default (the benchmark's settle())
};

// Balls of an interactive start when --balls is not given; 0 for an unknown name
// (common/scene_names.h lists the names).
std::uint32_t default_balls(const std::string& name);
// Tank bounds the scene needs for this many balls.
TankBounds scene_tank(const SceneSpec& spec);
// Most balls the scene holds in world's tank: the tank's capacity, or what its lattices fit with none touching
// (wide's tank, from scene_tank, fits the count it was sized for).
std::uint32_t scene_capacity(const World& world, const std::string& name);
// Puts the scene's balls in (queued or placed), as many as it holds; returns "" or a refusal that says how many
// it holds and how many went in.
std::string populate(World& world, const SceneSpec& spec);

}  // namespace fishtank
