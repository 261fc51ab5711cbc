// Restitution beyond the accuracy sweep (collision_sweep_test.cpp: every size
// pair, the floor and the player at every speed and onset phase): momentum
// through a ball-ball contact, every face of the tank (the sweep uses the
// floor; each upper face is its own branch of the wall law), a floor bounce
// under gravity against the contact model's exact answer, and the player
// sphere kinematic. Each within the default tolerance, in every kernel twin.

#include <catch2/catch.hpp>
#include <cmath>

#include "server/accuracy/reference.h"
#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

namespace {
constexpr float kE = 0.6f;
const float kTolerance = PhysicsParams{}.tolerance;
}  // namespace

TEST_CASE("a ball-ball contact rebounds at e and conserves momentum, for every size pair", "[physics][restitution]") {
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
  const float momentum = world.ball(0).vel.x * world.ball(0).vel.w + world.ball(1).vel.x * world.ball(1).vel.w;
  CHECK(momentum == Approx(kBallKinds[kind_a].mass - kBallKinds[kind_b].mass).margin(1e-4));
}

TEST_CASE("every face of the tank rebounds a ball at e, for every size", "[physics][restitution]") {
  const std::string variant = GENERATE(from_range(variant_names()));
  const int kind = GENERATE(0, 1, 2);
  const int axis = GENERATE(0, 1, 2);
  const bool upper = GENERATE(false, true);
  PhysicsParams params = open_space();
  World world(params, kernels_named(variant), 1, 1);
  const float r = 0.5f * kBallKinds[kind].diameter;
  const Vec3 lo = params.tank.min, hi = params.tank.max;
  float pos[3] = {0.5f * (lo.x + hi.x), 0.5f * (lo.y + hi.y), 0.5f * (lo.z + hi.z)};
  float vel[3] = {0.0f, 0.0f, 0.0f};
  const float face = upper ? (&hi.x)[axis] : (&lo.x)[axis];
  const float inward = upper ? -1.0f : 1.0f;  // from the face into the tank
  pos[axis] = face + inward * (r + 0.05f);
  vel[axis] = -inward * 2.0f;
  world.place_ball(kind, {pos[0], pos[1], pos[2]}, {vel[0], vel[1], vel[2]});
  auto apart = [&] {
    const Float4 p = world.ball(0).pos;
    return inward * ((&p.x)[axis] - face) > r;
  };
  step_through_contact(world, apart);
  const Float4 v = world.ball(0).vel;
  INFO(variant << " diameter " << 2 * r << ", axis " << axis << (upper ? " upper" : " lower") << " face");
  CHECK(inward * (&v.x)[axis] / 2.0f == Approx(kE).margin(kTolerance));
}

TEST_CASE("a ball dropped on the floor under gravity rebounds as the contact model's exact solution says",
          "[physics][restitution]") {
  const std::string variant = GENERATE(from_range(variant_names()));
  const int kind = GENERATE(0, 1, 2);
  const PhysicsParams params;  // default tank and gravity: gravity presses the ball in during the contact too
  World world(params, kernels_named(variant), 1, 1);
  const float r = 0.5f * kBallKinds[kind].diameter;
  world.place_ball(kind, {0.0f, r + 0.01f, 0.0f}, {0.0f, -3.0f, 0.0f});
  step_through_contact(world, [&] { return world.ball(0).pos.y > r; });
  const double g = params.gravity, m = kBallKinds[kind].mass;
  const double approach = std::sqrt(3.0 * 3.0 + 2.0 * g * 0.01);
  // In free flight since the overlap ended: Verlet is exact under constant gravity, so the speed at the exit is
  // that of the height climbed since.
  const double height = world.ball(0).pos.y - r, v = world.ball(0).vel.y;
  const double exit_speed = std::sqrt(v * v + 2.0 * g * height);
  const accuracy::ContactExit exact =
      accuracy::exact_contact({m, params.stiffness, accuracy::pair_damping(params.stiffness, kE, m)}, approach, g);
  REQUIRE(exact.ended);
  INFO(variant << " diameter " << 2 * r << ": " << exit_speed / approach << ", exact " << exact.exit_speed / approach);
  CHECK(exact.exit_speed / approach < kE - 0.01);  // gravity's share, which the check below must resolve
  CHECK(exit_speed / approach == Approx(exact.exit_speed / approach).margin(kTolerance));
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
