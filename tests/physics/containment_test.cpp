// A full tank, with the player sphere sweeping fast through the pile for 20
// simulated seconds: no ball leaves the tank, none is lost, every value stays
// finite, and the player stays inside. And the softest k the server accepts
// (softest_stiffness) still holds a full tank's pile inside, which a third of it does not.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "server/physics/world_measures.h"
#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

TEST_CASE("a full tank stays contained while the player ploughs through it", "[physics][containment][slow]") {
  PhysicsParams params;
  World world(params, kSseKernels, 2, 11);
  pour_and_settle(world, 6000, 60.0);
  REQUIRE(world.ball_count() == 6000);
  REQUIRE(world.pending() == 0);
  CHECK(escaped_or_invalid(world) == 0);
  CHECK(max_overlap_fraction(world) < 0.10f);  // the default k keeps overlaps under 10% of r_min

  const std::uint32_t player = world.add_player();
  const float speed = params.player_max_speed;
  // Sweep: a different axis direction every half second, through the pile and into the walls.
  const Vec3 directions[] = {{1, 0, 0}, {0, -1, 0}, {-1, 0, 0}, {0, 0, 1}, {0, 1, 0}, {0, 0, -1}, {1, -1, 1}};
  const int steps = static_cast<int>(20.0 / world.dt());
  const int turn_every = static_cast<int>(0.5 / world.dt());
  float fastest = 0.0f;
  for (int s = 0; s < steps; ++s) {
    if (s % turn_every == 0) world.set_player_velocity(player, directions[(s / turn_every) % 7] * speed);
    world.step();
    if (s % 500 != 0) continue;
    REQUIRE(escaped_or_invalid(world) == 0);
    fastest = std::max(fastest, max_speed(world));
    // The whole sphere stays inside, not only its centre.
    const Vec3 p = world.player_position(player);
    const float r = 0.5f * kPlayerDiameter, slack = 1e-4f;
    REQUIRE(p.x - r >= params.tank.min.x - slack);
    REQUIRE(p.x + r <= params.tank.max.x + slack);
    REQUIRE(p.y - r >= params.tank.min.y - slack);
    REQUIRE(p.y + r <= params.tank.max.y + slack);
    REQUIRE(p.z - r >= params.tank.min.z - slack);
    REQUIRE(p.z + r <= params.tank.max.z + slack);
  }
  CHECK(escaped_or_invalid(world) == 0);
  CHECK(world.ball_count() == 6000);
  // A fall the height of the tank reaches 28 m/s and the sphere adds its 10: a blow-up is far beyond.
  INFO("fastest ball seen: " << fastest << " m/s");
  CHECK(fastest < 50.0f);
}

TEST_CASE("at the softest k the server accepts a full tank's pile holds every ball inside, at a third of it not",
          "[physics][containment][slow]") {
  PhysicsParams params;
  params.stiffness = softest_stiffness(params);
  REQUIRE(validate(params).empty());
  World world(params, kSseKernels, 2, 11);
  pour_and_settle(world, 6000, 60.0);
  INFO("deepest overlap " << max_overlap_fraction(world) << " of the smallest radius");
  CHECK(escaped_or_invalid(world) == 0);
  CHECK(max_overlap_fraction(world) < 1.0f);  // no contact pressed in past the smaller radius

  // What the bound keeps out: a third as stiff, the pile presses balls through the floor.
  params.stiffness /= 3.0f;
  World soft(params, kSseKernels, 2, 11);
  pour_and_settle(soft, 6000, 60.0);
  CHECK(escaped_or_invalid(soft) > 0);
}
