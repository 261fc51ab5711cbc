#pragma once
// Small scenes shared by the physics tests.

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "server/physics/world.h"
#include "server/physics/world_measures.h"

namespace fishtank::test {

// Every kernel set this processor runs, for tests that must hold for each.
inline std::vector<std::string> variant_names() {
  std::vector<std::string> names{"scalar", "sse"};
  if (cpu_has_avx2()) names.push_back("avx2");
  return names;
}
inline const Kernels& kernels_named(const std::string& name) {
  if (name == "avx2") return kAvx2Kernels;
  return name == "sse" ? kSseKernels : kScalarKernels;
}

// Kinetic, gravitational and spring energy: what World::energy_added() bounds while damping only removes.
inline double total_energy(const World& w) { return kinetic_energy(w) + potential_energy(w) + elastic_energy(w); }

// No gravity, in a tank wide enough that nothing reaches a wall by accident.
inline PhysicsParams open_space() {
  PhysicsParams p;
  p.gravity = 0.0f;
  p.tank.min = {-50.0f, 0.0f, -50.0f};
  p.tank.max = {50.0f, 100.0f, 50.0f};
  return p;
}

// Steps until the balls have met and parted again, at most max_steps, and two steps more: the step whose
// window held the parting is then past (as the accuracy sweep reads it, server/accuracy/collisions.cpp).
template <class Apart>
inline void step_through_contact(World& world, Apart apart, int max_steps = 20000) {
  bool touched = false;
  for (int s = 0; s < max_steps; ++s) {
    world.step();
    if (!apart()) touched = true;
    if (touched && apart()) break;
  }
  for (int s = 0; s < 2; ++s) world.step();
}

// Every ball of a poured tank, stepped until the queue is empty and the pile is at rest.
inline void pour_and_settle(World& world, std::uint32_t balls, double max_seconds) {
  world.add_balls(balls);
  const int check_every = static_cast<int>(0.1 / world.dt());
  for (double t = 0.0; t < max_seconds; t += world.dt()) {
    world.step();
    if (world.steps() % check_every == 0 && world.pending() == 0 && kinetic_energy(world) / world.ball_count() < 1e-3)
      return;
  }
}

}  // namespace fishtank::test
