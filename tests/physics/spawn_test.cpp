// Pouring: balls enter at the top without overlapping anything, in equal
// numbers of each kind, and asking for more than the tank holds is refused
// with a reason while what fits is still accepted.

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <set>

#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

TEST_CASE("a new ball never overlaps another ball or a player", "[physics][spawn]") {
  World world(PhysicsParams{}, kSseKernels, 2, 7);
  world.add_player();
  world.add_balls(1500);
  std::set<std::uint32_t> seen;
  std::uint32_t checked = 0;
  while (world.pending() > 0 && world.time() < 30.0) {
    const std::uint32_t before = world.ball_count();
    world.step();
    if (world.ball_count() == before) continue;
    // Balls with ids >= before just appeared: compare them with everything.
    for (std::uint32_t i = 0; i < world.ball_count(); ++i) {
      if (world.ids()[i] < before) continue;
      const Float4& a = world.positions()[i];
      for (std::uint32_t j = 0; j < world.ball_count(); ++j) {
        if (j == i) continue;
        const Float4& b = world.positions()[j];
        float d = std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
        // One step of motion (< 0.01) may have passed since placement.
        REQUIRE(d > a.w + b.w - 0.02f);
      }
      Vec3 p = world.player_position(world.player_ids()[0]);
      REQUIRE(length(Vec3{a.x, a.y, a.z} - p) > a.w + 0.5f - 0.02f);
      ++checked;
    }
  }
  CHECK(world.pending() == 0);
  CHECK(checked == 1500);
}

TEST_CASE("kinds come in equal numbers", "[physics][spawn]") {
  World world(PhysicsParams{}, kSseKernels, 1, 3);
  world.add_balls(999);
  while (world.pending() > 0) world.step();
  std::array<int, kKindCount> count{};
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) ++count[world.kinds()[i]];
  CHECK(count == std::array<int, kKindCount>{333, 333, 333});
}

TEST_CASE("adding beyond capacity accepts what fits and says why not the rest", "[physics][spawn]") {
  World world(PhysicsParams{}, kSseKernels, 1, 1);
  const std::uint32_t capacity = world.capacity();
  CHECK(capacity > 5800);  // SPEC 1.5: roughly 6000 balls of the default mix
  CHECK(capacity < 6500);
  AddResult first = world.add_balls(capacity - 100);
  CHECK(first.accepted == capacity - 100);
  CHECK(first.refusal.empty());
  AddResult second = world.add_balls(1000);
  CHECK(second.accepted == 100);
  CHECK(second.refusal.find("added 100 of 1000") != std::string::npos);
  AddResult third = world.add_balls(1000);
  CHECK(third.accepted == 0);
  CHECK(world.pending() == capacity);
  CHECK(world.add_balls(-5).accepted == 0);
  CHECK(!world.add_balls(0).refusal.empty());
}
