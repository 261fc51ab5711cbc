// The scalar and SSE twins compute the same physics: the same trajectories
// over a short horizon (they differ only in the order of float additions),
// and the same settled pile over a long one, where chaos has long since
// separated individual trajectories.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

TEST_CASE("scalar and SSE trajectories agree over a short horizon", "[physics][variants]") {
  // Both twins start from the same settled pile, stirred by a player sphere,
  // so nearly every ball has several contacts throughout.
  World pile(PhysicsParams{}, kSseKernels, 2, 1);
  pour_and_settle(pile, 1000, 40.0);
  REQUIRE(pile.mean_neighbours() > 5.0);
  World scalar(PhysicsParams{}, kScalarKernels, 1, 1);
  World sse(PhysicsParams{}, kSseKernels, 2, 1);
  for (World* w : {&scalar, &sse}) {
    for (std::uint32_t id = 0; id < pile.ball_count(); ++id) {
      BallView b = pile.ball(id);
      w->place_ball(b.kind, {b.pos.x, b.pos.y, b.pos.z}, {b.vel.x, b.vel.y, b.vel.z});
    }
    const std::uint32_t player = w->add_player();
    w->set_player_velocity(player, {0.0f, -5.0f, 2.0f});
  }
  const int steps = 500;  // 0.4 s; differences then grow chaotically (3.5e-4 at 1000 steps)
  for (int s = 0; s < steps; ++s) {
    scalar.step();
    sse.step();
  }
  float worst = 0.0f;
  for (std::uint32_t id = 0; id < scalar.ball_count(); ++id) {
    Float4 a = scalar.ball(id).pos, b = sse.ball(id).pos;
    worst = std::max({worst, std::fabs(a.x - b.x), std::fabs(a.y - b.y), std::fabs(a.z - b.z)});
  }
  INFO("largest position difference after " << steps << " steps: " << worst);
  CHECK(worst < 1e-3f);
}

TEST_CASE("scalar and SSE settle into the same pile", "[physics][variants][slow]") {
  World scalar(PhysicsParams{}, kScalarKernels, 1, 5);
  World sse(PhysicsParams{}, kSseKernels, 2, 5);
  pour_and_settle(scalar, 1500, 40.0);
  pour_and_settle(sse, 1500, 40.0);
  REQUIRE(scalar.ball_count() == 1500);
  REQUIRE(sse.ball_count() == 1500);
  auto mean_height = [](const World& w) {
    double sum = 0.0;
    for (std::uint32_t i = 0; i < w.ball_count(); ++i) sum += w.positions()[i].y;
    return sum / w.ball_count();
  };
  INFO("mean height " << mean_height(scalar) << " vs " << mean_height(sse) << ", pile top " << scalar.pile_top()
                      << " vs " << sse.pile_top());
  CHECK(mean_height(scalar) == Approx(mean_height(sse)).epsilon(0.03));
  CHECK(scalar.pile_top() == Approx(sse.pile_top()).margin(1.5));
  CHECK(scalar.max_overlap_fraction() == Approx(sse.max_overlap_fraction()).margin(0.03));
}

TEST_CASE("the AVX2 build of the SSE kernels computes bit-identical states", "[physics][variants]") {
  if (!cpu_has_avx2()) {
    WARN("this processor has no AVX2; nothing to compare");
    return;
  }
  // Same source, same operations on the same lanes, no contraction into FMA:
  // only the instruction encoding differs, so the states must match exactly.
  World sse(PhysicsParams{}, kSseKernels, 2, 8);
  World avx2(PhysicsParams{}, kAvx2Kernels, 2, 8);
  for (World* w : {&sse, &avx2}) {
    w->add_balls(1500);
    w->set_player_velocity(w->add_player(), {2.0f, -3.0f, 1.0f});
    for (int s = 0; s < 3000; ++s) w->step();
  }
  CHECK(avx2.state_hash() == sse.state_hash());
}
