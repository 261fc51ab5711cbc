// Results do not depend on the number of worker threads: every ball's force
// is summed by one thread in a fixed order, so the state is bit-identical
// for 1, 2 and 4 threads (compared through a hash of every position and
// velocity, as Box2D does).

#include <catch2/catch.hpp>

#include "tests/physics/scenarios.h"

using namespace fishtank;

namespace {

std::uint64_t run(int threads) {
  World world(PhysicsParams{}, kSseKernels, threads, 99);
  world.add_balls(1200);
  const std::uint32_t player = world.add_player();
  world.set_player_velocity(player, {3.0f, -4.0f, 1.0f});
  for (int s = 0; s < 4000; ++s) {
    if (s == 2000) world.set_player_velocity(player, {-6.0f, 2.0f, 0.0f});
    world.step();
  }
  REQUIRE(world.threads() == threads);
  return world.state_hash();
}

}  // namespace

TEST_CASE("state is bit-identical for 1, 2 and 4 threads", "[physics][determinism]") {
  const std::uint64_t one = run(1);
  CHECK(run(2) == one);
  CHECK(run(4) == one);
}
