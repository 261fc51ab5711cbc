// Measured restitution (rebound / approach normal speed) is the e the damping
// was derived from, for every size pair, the walls and the player sphere, in
// both kernel twins.

#include <catch2/catch.hpp>
#include <cmath>

#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

namespace {
constexpr float kE = 0.6f;
constexpr float kTolerance = 0.03f;
}  // namespace

TEST_CASE("ball-ball restitution is e for every size pair", "[physics][restitution]") {
  const std::string variant = GENERATE(from_range(variant_names()));
  const auto [kind_a, kind_b] = GENERATE(table<int, int>({{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}}));
  World world(open_space(), kernels_named(variant), 1, 1);
  const float ra = 0.5f * kBallKinds[kind_a].diameter, rb = 0.5f * kBallKinds[kind_b].diameter;
  const float gap = 0.05f;
  world.place_ball(kind_a, {-ra - gap, 50.0f, 0.0f}, {1.0f, 0.0f, 0.0f});
  world.place_ball(kind_b, {rb + gap, 50.0f, 0.0f}, {-1.0f, 0.0f, 0.0f});
  auto apart = [&] { return world.ball(1).pos.x - world.ball(0).pos.x > ra + rb; };
  step_through_contact(world, apart);

  const float approach = 2.0f;
  const float rebound = world.ball(1).vel.x - world.ball(0).vel.x;
  INFO(variant << " diameters " << 2 * ra << " and " << 2 * rb << ": rebound " << rebound);
  CHECK(rebound / approach == Approx(kE).margin(kTolerance));
  // Momentum is conserved through the contact.
  const float momentum = world.ball(0).vel.x * world.ball(0).vel.w + world.ball(1).vel.x * world.ball(1).vel.w;
  CHECK(momentum == Approx(kBallKinds[kind_a].mass - kBallKinds[kind_b].mass).margin(1e-4));
}

TEST_CASE("ball-wall restitution is e for every size", "[physics][restitution]") {
  const std::string variant = GENERATE(from_range(variant_names()));
  const int kind = GENERATE(0, 1, 2);
  PhysicsParams params = open_space();
  World world(params, kernels_named(variant), 1, 1);
  const float r = 0.5f * kBallKinds[kind].diameter;
  world.place_ball(kind, {params.tank.min.x + r + 0.05f, 50.0f, 0.0f}, {-2.0f, 0.0f, 0.0f});
  auto apart = [&] { return world.ball(0).pos.x > params.tank.min.x + r; };
  step_through_contact(world, apart);
  INFO(variant << " diameter " << 2 * r);
  CHECK(world.ball(0).vel.x / 2.0f == Approx(kE).margin(kTolerance));
}

TEST_CASE("ball-floor restitution under gravity is e", "[physics][restitution]") {
  const std::string variant = GENERATE(from_range(variant_names()));
  PhysicsParams params;  // default tank and gravity
  World world(params, kernels_named(variant), 1, 1);
  // Dropped so it meets the floor at 3 m/s; gravity acts during the ~16 ms
  // contact too, which is why this check is looser than the others.
  world.place_ball(1, {0.0f, 1.0f + 0.01f, 0.0f}, {0.0f, -3.0f, 0.0f});
  auto apart = [&] { return world.ball(0).pos.y > 1.0f; };
  step_through_contact(world, apart);
  float approach = std::sqrt(3.0f * 3.0f + 2.0f * 9.81f * 0.01f);
  CHECK(world.ball(0).vel.y / approach == Approx(kE).margin(0.05));
}

TEST_CASE("ball-player restitution is e, the player being immovable", "[physics][restitution]") {
  const std::string variant = GENERATE(from_range(variant_names()));
  const int kind = GENERATE(0, 1, 2);
  World world(open_space(), kernels_named(variant), 1, 1);
  const std::uint32_t player = world.add_player();
  const Vec3 centre = world.player_position(player);
  const float reach = 0.5f * kBallKinds[kind].diameter + 0.5f * kPlayerDiameter;
  world.place_ball(kind, {centre.x + reach + 0.05f, centre.y, centre.z}, {-1.5f, 0.0f, 0.0f});
  auto apart = [&] { return world.ball(0).pos.x - centre.x > reach; };
  step_through_contact(world, apart);
  INFO(variant << " diameter " << kBallKinds[kind].diameter);
  CHECK(world.ball(0).vel.x / 1.5f == Approx(kE).margin(kTolerance));
  CHECK(world.player_position(player).x == centre.x);  // kinematic: balls do not push it
}
