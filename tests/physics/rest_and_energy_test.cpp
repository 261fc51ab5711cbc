// Two facts of the contact law beyond single collisions (contact_law.h): a
// pile at rest stands on k x (the dashpot's implicit factor does not soften
// the spring), and an elastic gas keeps its energy.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "server/physics/world_measures.h"
#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

TEST_CASE("a settled pile's floor contacts carry its weight on k x, within 0.5 %", "[physics][rest]") {
  World world(PhysicsParams{}, kSseKernels, 1, 1);
  world.add_balls(1000);
  while (world.time() < 90.0 &&
         (world.pending() > 0 || world.time() < 10.0 || kinetic_energy(world) / world.ball_count() > 1e-5))
    world.step();
  REQUIRE(world.pending() == 0);
  double floor = 0.0, weight = 0.0;
  const float k = world.params().stiffness, g = world.params().gravity, bottom = world.params().tank.min.y;
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) {
    const Float4 p = world.positions()[i];
    if (p.y - p.w < bottom) floor += double(k) * (bottom + p.w - p.y);
    weight += double(kBallKinds[world.kinds()[i]].mass) * g;
  }
  INFO("floor force / weight " << floor / weight << " at " << world.time() << " s, kinetic energy per ball "
                               << kinetic_energy(world) / world.ball_count() << " J");
  CHECK(kinetic_energy(world) / world.ball_count() <= 1e-5);
  CHECK(floor / weight == Approx(1.0).margin(0.005));
}

// Over 300 s at the default 13 steps per contact the gas gains about 1e-4 per 100 s
// (docs/accuracy.md); the drift falls with the step, and at 20 steps it is within 2e-4.
TEST_CASE("an elastic gas of 1000 balls keeps its energy over 300 s: within 5e-4 by default, 2e-4 at 20 steps",
          "[physics][energy]") {
  const auto [steps_per_contact, bound] = GENERATE(table<int, double>({{0, 5e-4}, {20, 2e-4}}));
  PhysicsParams params;
  params.restitution = 1.0f;
  params.gravity = 0.0f;
  params.steps_per_contact = steps_per_contact;
  World world(params, kSseKernels, 1, 7);
  world.add_balls(1000);
  while (world.pending() > 0) world.step();  // every ball poured in, moving at its spawn speed
  const auto energy = [&] { return kinetic_energy(world) + elastic_energy(world); };
  const double e0 = energy();
  double worst = 0.0, at_100 = 0.0;
  const double start = world.time();
  for (int second = 1; second <= 300; ++second) {
    while (world.time() < start + second) world.step();
    const double relative = (energy() - e0) / e0;
    worst = std::max(worst, std::fabs(relative));
    if (second == 100) at_100 = relative;
  }
  INFO(steps_per_contact << " steps per contact: worst |E - E0| / E0 " << worst << ", " << at_100 << " at 100 s");
  CHECK(worst <= bound);
}
