// Player spheres appear at distinct free points near the tank's centre, so
// viewers that join together do not start as one sphere.

#include "server/physics/player_spawn.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <vector>

#include "server/physics/world.h"

using namespace fishtank;

namespace {

const TankBounds kTank;
const Vec3 kCentre = kTank.min + kTank.size() * 0.5f;

float distance(Vec3 a, const Float4& b) { return length(a - Vec3{b.x, b.y, b.z}); }

bool inside_tank(Vec3 p) {
  const float r = 0.5f * kPlayerDiameter;
  return p.x - r >= kTank.min.x && p.y - r >= kTank.min.y && p.z - r >= kTank.min.z && p.x + r <= kTank.max.x &&
         p.y + r <= kTank.max.y && p.z + r <= kTank.max.z;
}

// Players join one after another, each placed where choose_player_spawn says.
std::vector<Float4> join(int count, const std::vector<Float4>& balls) {
  std::vector<Float4> players;
  for (int i = 0; i < count; ++i) {
    const Vec3 p = choose_player_spawn(kTank, players.data(), players.size(), balls.data(), balls.size());
    players.push_back({p.x, p.y, p.z, 0.5f * kPlayerDiameter});
  }
  return players;
}

void check_apart_inside_and_near(const std::vector<Float4>& players, float near) {
  for (std::size_t a = 0; a < players.size(); ++a) {
    const Vec3 p{players[a].x, players[a].y, players[a].z};
    INFO("player " << a << " at " << p.x << ", " << p.y << ", " << p.z);
    CHECK(inside_tank(p));
    CHECK(length(p - kCentre) <= near);
    for (std::size_t b = 0; b < a; ++b) CHECK(distance(p, players[b]) >= kPlayerDiameter);
  }
}

}  // namespace

TEST_CASE("in an empty tank the first player starts at the centre and eight start apart around it", "[spawn]") {
  const std::vector<Float4> players = join(8, {});
  const Vec3 first{players[0].x, players[0].y, players[0].z};
  CHECK(length(first - kCentre) == 0.0f);
  check_apart_inside_and_near(players, 3.0f);
}

TEST_CASE("a player does not start inside a ball while a point near the centre is free", "[spawn]") {
  // Small balls on every candidate point around the centre but one.
  const Vec3 free = kCentre + Vec3{1.5f, -1.5f, 1.5f};
  std::vector<Float4> balls;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k) {
        const Vec3 p = kCentre + Vec3{1.5f * i, 1.5f * j, 1.5f * k};
        if (length(p - free) > 0.01f) balls.push_back({p.x, p.y, p.z, 0.5f * kBallKinds[0].diameter});
      }
  const Vec3 p = choose_player_spawn(kTank, nullptr, 0, balls.data(), balls.size());
  CHECK(length(p - free) < 1e-4f);
}

TEST_CASE("beside a big ball at the centre, players start clear of it and of each other", "[spawn]") {
  const std::vector<Float4> balls{{kCentre.x, kCentre.y, kCentre.z, 0.5f * kBallKinds[2].diameter}};
  const std::vector<Float4> players = join(8, balls);
  check_apart_inside_and_near(players, 4.0f);
  for (const Float4& q : players) CHECK(distance({q.x, q.y, q.z}, balls[0]) >= balls[0].w + 0.5f * kPlayerDiameter);
}

TEST_CASE("more players than the points next to the centre still start apart, further out", "[spawn]") {
  const std::vector<Float4> players = join(40, {});
  check_apart_inside_and_near(players, 6.0f);
  // The first eight take the points next to the centre; the last of 40 cannot, and starts beyond them.
  float first_ring = 0.0f;
  for (int a = 0; a < 8; ++a) first_ring = std::max(first_ring, distance(kCentre, players[a]));
  CHECK(distance(kCentre, players.back()) > first_ring);
}

TEST_CASE("a world's players start apart, clear of its balls, inside the tank near the centre", "[spawn]") {
  World world(PhysicsParams{}, kScalarKernels, 1, 5);
  world.place_ball(2, kCentre, {0.0f, 0.0f, 0.0f});  // a big ball where the first player used to start
  std::vector<std::uint32_t> ids;
  for (int i = 0; i < 8; ++i) ids.push_back(world.add_player());
  std::vector<Float4> players;
  for (std::uint32_t id : ids) {
    const Vec3 p = world.player_position(id);
    players.push_back({p.x, p.y, p.z, 0.5f * kPlayerDiameter});
    CHECK(length(p - kCentre) >= 0.5f * kBallKinds[2].diameter + 0.5f * kPlayerDiameter);
  }
  check_apart_inside_and_near(players, 4.0f);
}
