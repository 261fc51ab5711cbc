// Results do not depend on the number of worker threads: every ball's force
// is summed by one thread in a fixed order, so the state is bit-identical
// for 1, 2 and 4 threads (compared through a hash of every position and
// velocity, as Box2D does).

#include <catch2/catch.hpp>

#include "tests/physics/scenarios.h"

using namespace fishtank;

namespace {

std::uint64_t run(const Kernels& kernels, int threads) {
  // 5000 balls, so that even 4 threads each get a chunk worth splitting off.
  PhysicsParams params;
  params.tank.min = {-40.0f, 0.0f, -40.0f};
  params.tank.max = {40.0f, 40.0f, 40.0f};
  World world(params, kernels, threads, 99);
  for (int b = 0; b < 5000; ++b) {
    Vec3 p{-39.0f + 3.05f * (b % 26), 1.6f + 3.05f * (b / 676), -39.0f + 3.05f * ((b / 26) % 26)};
    world.place_ball(b % kKindCount, p, Vec3{0.1f * (b % 7) - 0.3f, 0.0f, 0.1f * (b % 5) - 0.2f});
  }
  const std::uint32_t player = world.add_player();
  world.set_player_velocity(player, {3.0f, -4.0f, 1.0f});
  for (int s = 0; s < 1500; ++s) {
    if (s == 750) world.set_player_velocity(player, {-6.0f, 2.0f, 0.0f});
    world.step();
  }
  REQUIRE(world.threads() == threads);
  REQUIRE(world.escaped_or_invalid() == 0);
  return world.state_hash();
}

}  // namespace

TEST_CASE("state is bit-identical for 1, 2 and 4 threads", "[physics][determinism]") {
  const std::uint64_t one = run(kSseKernels, 1);
  CHECK(run(kSseKernels, 2) == one);
  CHECK(run(kSseKernels, 4) == one);
}

TEST_CASE("the AVX2 level's state is bit-identical for 1, 2 and 3 threads", "[physics][determinism]") {
  if (!cpu_has_avx2()) {
    WARN("this processor has no AVX2; nothing to compare");
    return;
  }
  // The AVX2 kernel carries two neighbouring balls per vector, so the chunk
  // bounds decide which balls share one: three threads start a chunk at an
  // odd index (1666 is even, 3333 odd) and pair every ball after it with
  // the other neighbour. Each half computes alone, so no state may change.
  const std::uint64_t one = run(kAvx2Kernels, 1);
  CHECK(run(kAvx2Kernels, 2) == one);
  CHECK(run(kAvx2Kernels, 3) == one);
}
