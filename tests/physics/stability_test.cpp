// Stiff and extreme scenes stay finite and contained (SPEC 7.2, first part).

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "server/physics/world_measures.h"
#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

TEST_CASE("contacts 100x stiffer than default stay finite and contained", "[physics][stability]") {
  PhysicsParams params;
  params.stiffness *= 100.0f;  // dt shrinks 10x with it
  World world(params, kSseKernels, 2, 3);
  pour_and_settle(world, 600, 12.0);
  CHECK(world.ball_count() == 600);
  CHECK(escaped_or_invalid(world) == 0);
  CHECK(max_overlap_fraction(world) < 0.01f);  // stiffer springs, smaller overlaps
}

TEST_CASE("a tank packed beyond capacity pushes itself apart without losing a ball", "[physics][stability]") {
  PhysicsParams params;
  World world(params, kSseKernels, 2, 3);
  // 8000 balls (capacity ~6100) on a lattice so tight that neighbours overlap
  // by up to a third of a diameter: the springs store a lot of energy.
  const int side = 20;  // 20 x 20 x 20 sites, 2 units apart
  for (int b = 0; b < side * side * side; ++b) {
    Vec3 p{-19.0f + 2.0f * (b % side), 1.0f + 2.0f * (b / (side * side)), -19.0f + 2.0f * ((b / side) % side)};
    world.place_ball(b % kKindCount, p, {0.0f, 0.0f, 0.0f});
  }
  double peak_energy = 0.0;
  for (int s = 0; s < static_cast<int>(3.0 / world.dt()); ++s) {
    world.step();
    if (s % 200 == 0) {
      REQUIRE(escaped_or_invalid(world) == 0);
      peak_energy = std::max(peak_energy, kinetic_energy(world));
    }
  }
  CHECK(escaped_or_invalid(world) == 0);
  CHECK(world.ball_count() == 8000);
  // Damping drains the stored energy: the pile ends far calmer than its peak.
  CHECK(kinetic_energy(world) < 0.1 * peak_energy);
}

TEST_CASE("restitution near 0 and at 1 stays contained and never holds more energy than the balls brought in",
          "[physics][stability]") {
  const float e = GENERATE(0.05f, 1.0f);
  PhysicsParams params;
  params.restitution = e;
  World world(params, kSseKernels, 2, 4);
  world.add_balls(800);
  double worst_ratio = 0.0;  // total energy / energy brought in, sampled
  for (int s = 1; s <= static_cast<int>(8.0 / world.dt()); ++s) {
    world.step();
    if (s % 100 == 0 && world.energy_added() > 0.0)
      worst_ratio = std::max(worst_ratio, total_energy(world) / world.energy_added());
  }
  INFO("e = " << e << ": largest total energy / energy brought in " << worst_ratio);
  CHECK(world.ball_count() + world.pending() == 800);
  CHECK(escaped_or_invalid(world) == 0);
  // Velocity Verlet misreads a contact's energy mid-contact by O((w dt)^2) of it (the soak test's bound); a
  // blow-up, or an e = 1 tank gaining a percent a second, is far above.
  CHECK(worst_ratio < 1.001);
  if (e < 0.1f) CHECK(total_energy(world) < 0.9 * world.energy_added());  // damping took its share
}

TEST_CASE("a pile of low e at the fewest steps per contact settles, and stays settled", "[physics][stability]") {
  // The dashpot takes the other contacts' forces from the last step (contact_law.h); an explicit
  // dashpot grew in dense piles whose damping rate x dt passes 0.5, as these do. How long a pour
  // takes to settle varies with the pour (docs/accuracy.md), so the bound is loose.
  const float e = GENERATE(0.05f, 0.01f);
  PhysicsParams params;
  params.restitution = e;
  params.steps_per_contact = PhysicsParams::kMinStepsPerContact;
  World world(params, kScalarKernels, 1, 4);  // the same trajectory on every x86-64 processor
  world.add_balls(1500);
  double settled_at = -1.0, most_since = 0.0;
  const int check_every = static_cast<int>(0.1 / world.dt());
  for (int s = 1; s <= static_cast<int>(150.0 / world.dt()); ++s) {
    world.step();
    if (s % check_every != 0) continue;
    const double per_ball = kinetic_energy(world) / world.ball_count();
    if (settled_at < 0.0 && world.pending() == 0 && per_ball < 1e-5) settled_at = world.time();
    if (settled_at >= 0.0) most_since = std::max(most_since, per_ball);
  }
  INFO("e = " << e << ": settled at " << settled_at << " s, kinetic energy per ball since at most " << most_since
              << " J, at 150 s " << kinetic_energy(world) / world.ball_count() << " J");
  CHECK(settled_at > 0.0);
  CHECK(most_since < 1e-4);
  CHECK(escaped_or_invalid(world) == 0);
  CHECK(max_overlap_fraction(world) < 0.1f);
}
