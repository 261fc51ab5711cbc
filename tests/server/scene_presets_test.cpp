// The scene presets and their (re)starts: every preset puts exactly its balls
// in its tank, none touching another; the dam-break column stands against
// one wall and collapses away from it; the drop's large balls start above the
// small bed; a restart with the same seed reproduces the run bit for bit, a
// switch of scene changes the tank, restarts ball ids and keeps the players
// inside.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "server/physics/world_measures.h"
#include "server/scenes/active_scene.h"

using namespace fishtank;

namespace {

SceneSpec preset(const char* name) {
  SceneSpec spec;
  spec.name = name;
  spec.balls = default_balls(name);
  return spec;
}

World world_for(const SceneSpec& spec) {
  PhysicsParams params;
  params.tank = scene_tank(spec);
  return World(params, kSseKernels, 1, spec.seed);
}

// The smallest gap between two balls' surfaces (negative: they overlap).
float closest_gap(const World& world) {
  const Float4* p = world.positions();
  float closest = 1e9f;
  for (std::uint32_t i = 0; i < world.ball_count(); ++i)
    for (std::uint32_t j = i + 1; j < world.ball_count(); ++j) {
      const float dx = p[i].x - p[j].x, dy = p[i].y - p[j].y, dz = p[i].z - p[j].z;
      closest = std::min(closest, std::sqrt(dx * dx + dy * dy + dz * dz) - p[i].w - p[j].w);
    }
  return closest;
}

void run_steps(World& world, int steps) {
  for (int s = 0; s < steps; ++s) world.step();
}

}  // namespace

TEST_CASE("every placed preset holds exactly its balls, inside its tank, none touching", "[scenes]") {
  for (const char* name : {"wide", "dam-break", "drop"}) {
    INFO(name);
    const SceneSpec spec = preset(name);
    World world = world_for(spec);
    REQUIRE(populate(world, spec).empty());
    CHECK(world.ball_count() == spec.balls);
    CHECK(escaped_or_invalid(world) == 0);
    CHECK(closest_gap(world) > 0.0f);
  }
  const SceneSpec tank = preset("tank");
  World poured = world_for(tank);
  REQUIRE(populate(poured, tank).empty());
  CHECK(poured.ball_count() + poured.pending() == 1000);  // poured in from the top over the first steps
}

TEST_CASE("a placed scene filled to what it says it holds takes every ball with none touching", "[scenes]") {
  for (const char* name : {"dam-break", "drop"}) {
    INFO(name);
    SceneSpec spec = preset(name);
    World world = world_for(spec);
    spec.balls = scene_capacity(world, name);
    CHECK(spec.balls > default_balls(name));
    REQUIRE(populate(world, spec).empty());
    CHECK(world.ball_count() == spec.balls);
    CHECK(escaped_or_invalid(world) == 0);
    CHECK(closest_gap(world) > 0.0f);
  }
}

TEST_CASE("one ball more than a scene holds places what it holds and says both counts", "[scenes]") {
  for (const char* name : {"dam-break", "drop"}) {
    INFO(name);
    SceneSpec spec = preset(name);
    World world = world_for(spec);
    const std::uint32_t holds = scene_capacity(world, name);
    spec.balls = holds + 1;
    CHECK(populate(world, spec) == "the " + std::string(name) + " scene holds at most " + std::to_string(holds) +
                                       " balls; " + std::to_string(holds + 1) + " were asked for, " +
                                       std::to_string(holds) + " placed");
    CHECK(world.ball_count() == holds);
    CHECK(closest_gap(world) > 0.0f);
  }
}

TEST_CASE("the dam-break column stands against the -x wall and spreads across the floor once released", "[scenes]") {
  const SceneSpec spec = preset("dam-break");
  World world = world_for(spec);
  REQUIRE(populate(world, spec).empty());
  const auto front = [&] {
    float x = -1e9f;
    for (std::uint32_t i = 0; i < world.ball_count(); ++i) x = std::max(x, world.positions()[i].x);
    return x;
  };
  const float tank_min_x = world.params().tank.min.x;
  const float start = front();
  CHECK(start < tank_min_x + 6.0f);
  run_steps(world, static_cast<int>(2.0 / world.dt()));
  INFO("front from x = " << start << " to " << front());
  CHECK(front() > start + 10.0f);  // a 17-unit column falling over reaches well beyond its width
  CHECK(escaped_or_invalid(world) == 0);
}

TEST_CASE("the drop scene's large balls all start above its bed of small ones", "[scenes]") {
  const SceneSpec spec = preset("drop");
  World world = world_for(spec);
  REQUIRE(populate(world, spec).empty());
  float bed_top = -1e9f, lowest_large = 1e9f;
  std::uint32_t large = 0;
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) {
    const Float4& p = world.positions()[i];
    if (world.kinds()[i] == 0) bed_top = std::max(bed_top, p.y + p.w);
    if (world.kinds()[i] == kKindCount - 1) lowest_large = std::min(lowest_large, p.y - p.w), ++large;
  }
  CHECK(large == spec.balls / 10);
  CHECK(lowest_large > bed_top + 10.0f);
}

TEST_CASE("a restart with the same seed reproduces the run bit for bit, another seed does not", "[scenes]") {
  for (const char* name : {"tank", "wide"}) {
    INFO(name);
    SceneChoice choice;
    choice.name = name;
    choice.balls = 300;
    ActiveScene scene(choice);
    PhysicsParams params;
    params.tank = scene.first_tank();
    World world(params, kSseKernels, 1, 1);
    REQUIRE(scene.start(world).empty());
    run_steps(world, 400);
    const std::uint64_t first = state_hash(world);
    REQUIRE(scene.start(world).empty());  // the same scene, the same seed
    CHECK(world.ball_count() <= 300);
    run_steps(world, 400);
    CHECK(state_hash(world) == first);
    REQUIRE(scene.start(world, std::nullopt, 2).empty());
    run_steps(world, 400);
    CHECK(state_hash(world) != first);
    CHECK(scene.seed() == 2);
    CHECK(scene.start_count() == 3);
  }
}

TEST_CASE("switching scene changes the tank, restarts ball ids at 0 and keeps every player inside", "[scenes]") {
  ActiveScene scene(SceneChoice{});  // each scene's own number of balls
  PhysicsParams params;
  params.tank = scene.first_tank();
  World world(params, kSseKernels, 1, 1);
  REQUIRE(scene.start(world).empty());
  const std::uint32_t a = world.add_player(), b = world.add_player();
  run_steps(world, 2000);
  REQUIRE(scene.start(world, std::string("wide")).empty());
  CHECK(scene.name() == "wide");
  CHECK(world.params().tank.size().x > 40.0f);
  CHECK(world.ball_count() == default_balls("wide"));
  const std::uint32_t* ids = world.ids();
  CHECK(*std::max_element(ids, ids + world.ball_count()) == default_balls("wide") - 1);
  const TankBounds& t = world.params().tank;
  for (std::uint32_t id : {a, b}) {
    const Vec3 p = world.player_position(id);
    CHECK(p.x > t.min.x);
    CHECK(p.x < t.max.x);
    CHECK(p.y > t.min.y);
    CHECK(p.y < t.max.y);
  }
  const Vec3 apart = world.player_position(a) - world.player_position(b);
  CHECK(std::sqrt(dot(apart, apart)) >= kPlayerDiameter);
  run_steps(world, 500);
  CHECK(escaped_or_invalid(world) == 0);
}

TEST_CASE("a scene whose tank holds fewer balls than --max-balls says so, and its capacity is the limit", "[scenes]") {
  SceneChoice choice;
  choice.balls = 300;
  choice.max_balls = 6000;  // the tank holds 6111
  ActiveScene scene(choice);
  PhysicsParams params;
  params.tank = scene.first_tank();
  World world(params, kSseKernels, 1, 1);
  REQUIRE(scene.start(world).empty());
  CHECK(scene.limit_note().empty());
  CHECK(world.max_balls() == 6000);
  REQUIRE(scene.start(world, std::string("wide")).empty());  // 300 balls: a narrow tank
  REQUIRE(world.capacity() < 6000);
  CHECK(world.max_balls() == world.capacity());
  CHECK_THAT(scene.limit_note(),
             Catch::Contains("wide") && Catch::Contains("--max-balls") && Catch::Contains("asked for 6000"));
  REQUIRE(scene.start(world, std::string("tank")).empty());
  CHECK(scene.limit_note().empty());
  CHECK(world.max_balls() == 6000);
}

TEST_CASE("every scene keeps to --max-balls 500: the tank's pour and the wide scene's lattice, each saying so",
          "[scenes]") {
  SceneChoice choice;  // no --balls: the wide scene's own 6000
  choice.max_balls = 500;
  ActiveScene scene(choice);
  PhysicsParams params;
  params.tank = scene.first_tank();
  World world(params, kSseKernels, 1, 1);
  CHECK(scene.start(world) == "the tank scene: --max-balls lets in 500 of the 1000 balls asked for");
  const std::string refusal = scene.start(world, std::string("wide"));
  CHECK(world.ball_count() == 500);
  CHECK(refusal == "the wide scene: --max-balls lets in 500 of the 6000 balls asked for");
}
