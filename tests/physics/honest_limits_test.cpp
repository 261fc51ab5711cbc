// The world says when it cannot do what it was asked: more balls than the
// tank holds are refused with a message, and an overlap beyond 10 % of the
// smaller radius (a stiffness too soft for the load) gives a warning.

#include <algorithm>
#include <catch2/catch.hpp>

#include "server/physics/world_measures.h"
#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

TEST_CASE("a ball limit above the tank's capacity is refused and the limit kept", "[physics][limits]") {
  World world(PhysicsParams{}, kScalarKernels, 1, 1);
  const std::uint32_t capacity = world.capacity();
  const std::string refusal = world.set_max_balls(capacity + 1);
  INFO(refusal);
  CHECK(refusal.find(std::to_string(capacity)) != std::string::npos);  // says what fits
  CHECK(world.max_balls() == capacity);
  CHECK(world.set_max_balls(capacity / 2).empty());
  CHECK(world.max_balls() == capacity / 2);
}

TEST_CASE("a resting overlap beyond 10 % of the smaller radius gives a warning, a light one none",
          "[physics][limits]") {
  // A unit ball resting on the floor sinks m g / k: 4 % and 16 % of r = 0.5 at these k.
  const float sink = GENERATE(0.02f, 0.08f);
  PhysicsParams params;
  params.stiffness = 9.81f / sink;
  World world(params, kScalarKernels, 1, 1);
  world.place_ball(0, {0.0f, 0.5f, 0.0f}, {});
  while (world.time() < 30.0) world.step();  // a few hundred contact durations: damped to rest
  const std::string warning = overlap_warning(world);
  INFO("sink " << sink << ": overlap " << max_overlap_fraction(world) << ", " << warning);
  CHECK(max_overlap_fraction(world) == Approx(sink / 0.5f).epsilon(0.02));
  CHECK(warning.empty() == (sink / 0.5f <= kOverlapWarning));
}

TEST_CASE("an impact's deep overlap is reported but gives no warning", "[physics][limits]") {
  // 28 m/s onto the floor, as after a fall through the tank: damped, about 28 % of r at its deepest.
  PhysicsParams params;
  params.gravity = 0.0f;
  World world(params, kScalarKernels, 1, 1);
  world.place_ball(0, {0.0f, 0.6f, 0.0f}, {0.0f, -28.0f, 0.0f});
  float deepest = 0.0f;
  for (int s = 0; s < 40; ++s) {
    world.step();
    deepest = std::max(deepest, max_overlap_fraction(world));
    CHECK(overlap_warning(world).empty());
  }
  CHECK(deepest > 0.25f);
}
TEST_CASE("the HUD's contacts count each touching pair once and each wall contact, its overlap the deepest",
          "[physics][limits]") {
  World world(open_space(), kScalarKernels, 1, 1);
  const float r = kBallKinds[0].diameter / 2;
  world.place_ball(0, {0.0f, 50.0f, 0.0f}, {});
  world.place_ball(0, {2 * r - 0.2f * r, 50.0f, 0.0f}, {});       // overlaps the first by 20 % of r
  world.place_ball(0, {4 * r - 0.1f * r, 50.0f, 0.0f}, {});       // a gap of 0.1 r: listed, not touching
  world.place_ball(0, {-50.0f + r - 0.1f * r, 50.0f, 0.0f}, {});  // 10 % into the wall at x = -50
  world.step();                                                   // the lists are built
  const ContactFigures figures = contact_figures(world);
  CHECK(figures.contacts == 2);
  CHECK(figures.max_overlap == Approx(0.2f).epsilon(0.05));  // the first step pushes them a little apart
  CHECK(max_overlap_fraction(world) == figures.max_overlap);
}
