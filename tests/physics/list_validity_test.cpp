// The neighbour lists hold every touching pair at every step: the world keeps
// them past skin / 2 only after checking each ball that moved that far
// (World::lists_hold), so fast balls flying into a pile must never reach a
// ball their list lacks.

#include <algorithm>
#include <catch2/catch.hpp>
#include <set>
#include <utility>

#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

namespace {

// Touching pairs (i < j, sorted indices) at the world's positions, by brute force.
std::set<std::pair<std::uint32_t, std::uint32_t>> touching_pairs(const World& world) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
  const Float4* p = world.positions();
  for (std::uint32_t i = 0; i < world.ball_count(); ++i)
    for (std::uint32_t j = i + 1; j < world.ball_count(); ++j) {
      const float dx = p[i].x - p[j].x, dy = p[i].y - p[j].y, dz = p[i].z - p[j].z, reach = p[i].w + p[j].w;
      if (dx * dx + dy * dy + dz * dz < reach * reach) pairs.insert({i, j});
    }
  return pairs;
}

std::set<std::pair<std::uint32_t, std::uint32_t>> listed_pairs(const World& world) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
  world.neighbour_list().for_each_list([&](std::uint32_t i, ListView list) {
    for (std::uint32_t k = 0; k < list.count; ++k) pairs.insert({std::min(i, list[k]), std::max(i, list[k])});
  });
  return pairs;
}

// Steps the world, and after every step requires each touching pair to be in
// the lists; returns the number of touching pairs seen.
std::size_t step_checking_lists(World& world, int steps) {
  std::size_t contacts = 0;
  for (int s = 0; s < steps; ++s) {
    world.step();
    const auto touching = touching_pairs(world);
    const auto listed = listed_pairs(world);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> missing;
    std::set_difference(touching.begin(), touching.end(), listed.begin(), listed.end(), std::back_inserter(missing));
    INFO("step " << s << ": " << missing.size() << " touching pairs missing from the lists");
    REQUIRE(missing.empty());
    contacts += touching.size();
  }
  return contacts;
}

// Balls a and b (and the ghosts after them) at their positions at a build
// and now, with the grid of that build in the default 40-unit tank (12 cells
// of 3.33 per axis) and the default skin.
struct TwoBalls {
  NeighbourList list;
  AlignedVector<Float4> at_build, now;
};
TwoBalls two_balls(Float4 a_build, Float4 b_build, Float4 a_now, Float4 b_now) {
  TwoBalls t;
  t.list.configure(TankBounds{}, PhysicsParams::kStartSkin);
  t.at_build = {a_build, b_build};
  t.now = {a_now, b_now};
  for (std::uint32_t g = 0; g < kGhostSlots; ++g) t.at_build.push_back(kGhostPos), t.now.push_back(kGhostPos);
  std::vector<std::uint32_t> order;
  t.list.sort(t.at_build.data(), 2, order);
  REQUIRE(order == std::vector<std::uint32_t>{0, 1});  // a's cell comes first: indices stay
  return t;
}

}  // namespace

TEST_CASE("the lists hold every touching pair at every step while fast balls fly into a pile",
          "[physics][broadphase]") {
  const std::string variant = GENERATE(from_range(variant_names()));
  INFO(variant);
  PhysicsParams params;
  World world(params, kernels_named(variant), 2, 3);
  // A settled pile...
  pour_and_settle(world, 400, 30.0);
  REQUIRE(world.ball_count() == 400);
  // ...hit by small balls thrown at 20 units/s (the wide scene's fastest move
  // about that fast), and by the player sweeping through it at full speed.
  for (int b = 0; b < 12; ++b) {
    const float side = b % 2 ? 1.0f : -1.0f;
    world.place_ball(0, {side * 19.0f, 2.0f + 1.5f * b, -10.0f + 1.7f * b}, {-side * 20.0f, -1.0f, 1.0f});
  }
  const std::uint32_t player = world.add_player();
  world.set_player_velocity(player, Vec3{1.0f, -0.3f, 0.5f} * params.player_max_speed);

  const std::uint64_t rebuilds_before = world.rebuilds(), kept_before = world.lists_kept_by_checks();
  const std::size_t contacts_checked = step_checking_lists(world, 1500);
  const std::uint64_t rebuilds = world.rebuilds() - rebuilds_before, kept = world.lists_kept_by_checks() - kept_before;
  INFO("rebuilds " << rebuilds << ", lists kept after checking the strayed balls " << kept);
  CHECK(contacts_checked > 1500 * 250);  // a pile, not a gas
  CHECK(kept > 100);                     // the path under test ran often
  CHECK(rebuilds > 10);
}

TEST_CASE("two balls closing head-on from beyond the skin get a rebuild before they touch unlisted",
          "[physics][broadphase]") {
  // Each pair starts skin * (1 + extra) apart, beyond each other's lists, and
  // closes at 20 + 20 or 20 + 8 units/s: they touch when the faster has moved
  // more than the half skin after which the lists are only kept if checked
  // (with 20 + 8 the slower ball stays under the half skin: only the faster
  // one is checked).
  // Only the check of the strayed balls can see the contact coming; nothing else
  // moves.
  const std::string variant = GENERATE(from_range(variant_names()));
  INFO(variant);
  PhysicsParams params = open_space();
  params.skin = PhysicsParams::kStartSkin;  // fixed: each pair starts a known distance beyond it
  World world(params, kernels_named(variant), 1, 3);
  // A thousand resting balls well away from the pairs: for a dozen balls
  // alone a rebuild costs less than checking even one (World::lists_hold),
  // and the check is what this test is about.
  for (int x = 0; x < 10; ++x)
    for (int y = 0; y < 10; ++y)
      for (int z = 0; z < 10; ++z)
        world.place_ball(0, {-45.0f + 1.5f * x, 5.0f + 1.5f * y, -45.0f + 1.5f * z}, {0.0f, 0.0f, 0.0f});
  const float extras[] = {0.1f, 0.2f, 0.3f}, slower[] = {20.0f, 8.0f};
  for (int pair = 0; pair < 6; ++pair) {
    const float gap = 1.0f + params.skin * (1.0f + extras[pair % 3]);  // centres: two radii 0.5, the skin and more
    const Vec3 centre{-40.0f + 16.0f * pair, 50.0f, 0.0f};
    world.place_ball(0, centre - Vec3{0.5f * gap, 0.0f, 0.0f}, {20.0f, 0.0f, 0.0f});
    world.place_ball(0, centre + Vec3{0.5f * gap, 0.0f, 0.0f}, {-slower[pair / 3], 0.0f, 0.0f});
  }
  const std::size_t contacts = step_checking_lists(world, 60);
  CHECK(contacts > 0);                      // they met...
  CHECK(world.lists_kept_by_checks() > 0);  // ...after steps with strayed balls and kept lists
  CHECK(world.rebuilds() >= 2);             // and a rebuild came before each contact
}

TEST_CASE("the check finds a contact between two balls that both moved well past the skin", "[physics][broadphase]") {
  // Two small balls, 3.5 apart at the build, each moved 1.25 towards the
  // other and now touch. From where ball a is now, b's position at the build
  // lies 2.25 away, in the next cell along x, whose face is 2.23 away: a
  // search that reached only r_a + the largest radius + skin (2.2) would skip
  // that cell and miss the contact; the check widens its reach by how far
  // balls have moved.
  TankBounds tank;  // 40 units, 12 cells of 3.33 per axis: a face at x = 6.667
  const float face = tank.min.x + 8.0f * tank.size().x / 12.0f, moved = 1.25f;
  const Float4 a_now{face - 2.23f, 21.5f, 1.5f, 0.5f}, b_now{a_now.x + 1.0f, 21.5f, 1.5f, 0.5f};
  const Float4 a_build{a_now.x - moved, 21.5f, 1.5f, 0.5f}, b_build{a_now.x + 2.25f, 21.5f, 1.5f, 0.5f};
  auto [list, at_build, now] = two_balls(a_build, b_build, a_now, b_now);

  REQUIRE(list.can_check(moved));
  CHECK(list.misses_contact(0, now.data(), at_build.data(), moved));
  // Apart again, nothing is missing.
  now[1].x += 0.1f;
  CHECK_FALSE(list.misses_contact(0, now.data(), at_build.data(), moved));
}

TEST_CASE("the check finds a contact between two large balls whose build positions lie two cells apart",
          "[physics][broadphase]") {
  // Two large balls (radius 1.5), 4.9 apart at the build, each moved 1.0
  // towards the other and now touch. From where ball a is now, b's position
  // at the build lies 3.9 away, in the second cell along x from a's: the 27
  // cells around a's do not hold it (until the check searched as many cells
  // as its reach takes, it could not vouch for a large ball once balls had
  // moved ~0.3, and the lists were rebuilt). Past a large ball's search of two
  // cells each side, the check does not search and answers "missing".
  TankBounds tank;  // 40 units, 12 cells of 3.33 per axis
  const float edge = tank.size().x / 12.0f, face = tank.min.x + 7.0f * edge, moved = 1.0f;
  const Float4 a_now{face - 0.3f, 21.5f, 1.5f, 1.5f}, b_now{a_now.x + 2.9f, 21.5f, 1.5f, 1.5f};
  const Float4 a_build{a_now.x - moved, 21.5f, 1.5f, 1.5f}, b_build{a_now.x + 3.9f, 21.5f, 1.5f, 1.5f};
  REQUIRE(b_build.x > face + edge);  // two cells on from a's
  auto [list, at_build, now] = two_balls(a_build, b_build, a_now, b_now);

  REQUIRE(list.can_check(moved));
  CHECK(list.misses_contact(0, now.data(), at_build.data(), moved));
  CHECK(list.misses_contact(1, now.data(), at_build.data(), moved));  // and from b's side
  now[1].x += 0.2f;                                                   // apart again
  CHECK_FALSE(list.misses_contact(0, now.data(), at_build.data(), moved));
  CHECK_FALSE(list.misses_contact(1, now.data(), at_build.data(), moved));
  // The limit: the largest diameter + moved within two cells' width.
  CHECK(list.can_check(2.0f * edge - kMaxBallDiameter - 0.01f));
  CHECK_FALSE(list.can_check(2.0f * edge - kMaxBallDiameter + 0.01f));
  CHECK(list.misses_contact(0, now.data(), at_build.data(), 2.0f * edge - kMaxBallDiameter + 0.01f));
}

TEST_CASE("the skin follows the motion: sqrt(2 kSkinCostRatio x drift per step), within its bounds",
          "[physics][broadphase]") {
  // Balls 4 apart in open space, all at one velocity: nothing touches, and the
  // lists last until they have drifted skin / 2. Fast balls take the widest
  // skin, creeping ones the narrowest, and between the two the rule's.
  const float speed = GENERATE(10.0f, 1.0f, 0.03f);
  INFO("speed " << speed);
  World world(open_space(), kScalarKernels, 1, 3);
  for (int x = 0; x < 8; ++x)
    for (int y = 0; y < 8; ++y)
      for (int z = 0; z < 8; ++z)
        world.place_ball(0, {-16.0f + 4.0f * x, 20.0f + 4.0f * y, -16.0f + 4.0f * z}, {speed, 0.0f, 0.0f});
  REQUIRE(world.skin() == PhysicsParams::kStartSkin);
  const float rule = std::sqrt(2.0f * PhysicsParams::kSkinCostRatio * speed * world.dt());
  const int steps = int(4.0f / (speed * world.dt()) * std::max(rule, PhysicsParams::kStartSkin));  // a few builds
  for (int s = 0; s < steps; ++s) world.step();
  CHECK(world.rebuilds() >= 3);
  if (rule > PhysicsParams::kMaxSkin)
    CHECK(world.skin() == PhysicsParams::kMaxSkin);
  else if (rule < PhysicsParams::kMinSkin)
    CHECK(world.skin() == PhysicsParams::kMinSkin);
  else
    CHECK(world.skin() == Approx(rule).epsilon(0.02));
}

TEST_CASE("a given skin stays, and the adaptive one widens while balls bounce and narrows once they rest",
          "[physics][broadphase]") {
  // Balls apart on the floor, thrown up at 10 m/s: they bounce lower each
  // time (e = 0.6) and come to rest on the floor in about 5 s.
  const std::string variant = GENERATE(from_range(variant_names()));
  INFO(variant);
  for (const float given : {PhysicsParams::kStartSkin, 0.0f}) {
    PhysicsParams params;
    params.skin = given;
    World world(params, kernels_named(variant), 2, 3);
    for (int x = 0; x < 8; ++x)
      for (int z = 0; z < 8; ++z)
        world.place_ball(0, {-16.0f + 4.0f * x, 0.5f, -16.0f + 4.0f * z}, {0.0f, 10.0f, 0.0f});
    float widest = 0.0f;
    for (int s = 0; s < int(8.0 / world.dt()); ++s) {
      world.step();
      widest = std::max(widest, world.skin());
    }
    REQUIRE(kinetic_energy(world) / world.ball_count() < 1e-6);  // at rest
    if (given > 0.0f) {
      CHECK(widest == given);
      CHECK(world.skin() == given);
    } else {
      CHECK(widest == PhysicsParams::kMaxSkin);
      CHECK(world.skin() == PhysicsParams::kMinSkin);
    }
  }
}
