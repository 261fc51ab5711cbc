// The world says when it cannot do what it was asked: more balls than the
// tank holds are refused with a message, and an overlap beyond 10 % of the
// smaller radius (a stiffness too soft for the load) gives a warning.

#include <catch2/catch.hpp>

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

TEST_CASE("an overlap beyond 10 % of the smaller radius gives a warning, a light touch none", "[physics][limits]") {
  const float overlap = GENERATE(0.02f, 0.08f);  // of r = 0.5: 4 % and 16 %
  World world(open_space(), kScalarKernels, 1, 1);
  world.place_ball(0, {-0.5f + 0.5f * overlap, 50.0f, 0.0f}, {});
  world.place_ball(0, {0.5f - 0.5f * overlap, 50.0f, 0.0f}, {});
  world.step();  // the lists exist from the first step
  const std::string warning = world.overlap_warning();
  INFO("overlap " << overlap << ": " << warning);
  CHECK(warning.empty() == (overlap / 0.5f <= kOverlapWarning));
}
