// Extreme use (SPEC 7.2): a tank over-filled three times by add commands, balls
// added to a full tank, and a long soak of a full tank. Always finite,
// contained, every ball accounted for, and the total energy never above the
// energy the balls brought in.

#include <catch2/catch.hpp>
#include <cmath>

#include "server/physics/world_measures.h"
#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

TEST_CASE("asking for three tanks' worth of balls fills one, refuses the rest, and stays contained",
          "[physics][extreme][slow]") {
  World world(PhysicsParams{}, kSseKernels, 2, 21);
  std::uint32_t accepted = 0;
  for (int request = 0; request < 18; ++request) {  // 18 x 1000 = 3 x capacity
    AddResult r = world.add_balls(1000);
    accepted += r.accepted;
    if (accepted >= world.capacity()) CHECK_FALSE(r.refusal.empty());
    for (int s = 0; s < 1000; ++s) world.step();
  }
  CHECK(accepted == world.capacity());
  // Whatever could not pour in yet waits at the top; nothing is lost.
  for (int s = 0; s < static_cast<int>(40.0 / world.dt()) && world.pending() > 0; ++s) world.step();
  INFO("in the tank " << world.ball_count() << ", still queued " << world.pending() << ", pile top "
                      << pile_top(world));
  CHECK(world.ball_count() + world.pending() == world.capacity());
  CHECK(escaped_or_invalid(world) == 0);
  CHECK(pile_top(world) <= world.params().tank.max.y + 0.01f);
  CHECK(max_overlap_fraction(world) < 0.15f);
}

TEST_CASE("a full tank soaked for 120 simulated seconds keeps every ball and never gains energy",
          "[physics][extreme][slow]") {
  World world(PhysicsParams{}, kSseKernels, 2, 22);
  world.add_balls(6000);
  const int steps = static_cast<int>(120.0 / world.dt());
  double worst_ratio = 0.0;
  for (int s = 1; s <= steps; ++s) {
    world.step();
    if (s % 1000 != 0) continue;
    REQUIRE(escaped_or_invalid(world) == 0);
    const double energy = total_energy(world);
    REQUIRE(std::isfinite(energy));
    worst_ratio = std::max(worst_ratio, energy / world.energy_added());
  }
  INFO("largest total energy / energy brought in: " << worst_ratio);
  CHECK(world.ball_count() == 6000);
  CHECK(world.pending() == 0);
  // Damping only removes energy; what velocity Verlet measures mid-contact can
  // exceed the true value by O((w dt)^2) of the contact's energy, a transient
  // seen as 4e-5 of the total when the first balls hit the floor before any
  // energy has been dissipated. An energy blow-up would be orders above this.
  CHECK(worst_ratio < 1.001);
  // At the end the pile is at rest: what is left is potential and spring energy.
  CHECK(kinetic_energy(world) / world.ball_count() < 1e-3);
}

TEST_CASE("balls added to a full, settled tank wait at the top instead of being forced in", "[physics][extreme]") {
  World world(PhysicsParams{}, kSseKernels, 2, 23);
  pour_and_settle(world, 5800, 60.0);
  REQUIRE(world.ball_count() == 5800);
  AddResult more = world.add_balls(1000);
  CHECK(more.accepted == world.capacity() - 5800);
  CHECK_FALSE(more.refusal.empty());
  for (int s = 0; s < static_cast<int>(10.0 / world.dt()); ++s) world.step();
  CHECK(world.ball_count() + world.pending() == world.capacity());
  CHECK(escaped_or_invalid(world) == 0);
  CHECK(max_overlap_fraction(world) < 0.15f);
}

TEST_CASE("a player velocity too large to square in a float is clamped to the top speed, not stopped",
          "[physics][extreme]") {
  World world(PhysicsParams{}, kScalarKernels, 1, 1);
  const std::uint32_t id = world.add_player();
  const Vec3 start = world.player_position(id);
  REQUIRE(world.set_player_velocity(id, {3e38f, 0.0f, 0.0f}));  // |v|^2 overflows a float
  for (int s = 0; s < 100; ++s) world.step();
  const Vec3 moved = world.player_position(id) - start;
  const float expected = world.params().player_max_speed * 100 * world.dt();
  CHECK(moved.x == Approx(expected).epsilon(1e-3));
  CHECK(moved.y == 0.0f);
  CHECK(moved.z == 0.0f);
}
