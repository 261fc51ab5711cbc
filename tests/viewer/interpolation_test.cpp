// Snapshot interpolation: the frame shows a state between the two snapshots
// around the render time, so motion is smooth whatever the frame rate.

#include "viewer/net/interpolation.h"

#include <catch2/catch.hpp>

#include "viewer/net/snapshot_buffer.h"

using namespace fishtank;
using namespace fishtank::viewer;

namespace {

ServerInfo info_with_player(std::uint32_t player) {
  ServerInfo info;
  info.kinds.assign(kBallKinds.begin(), kBallKinds.end());
  info.has_player = true;
  info.player_id = player;
  return info;
}

// One ball (kind 2) at quantised x = qx; one player (id 7) at player_x.
std::shared_ptr<Snapshot> snapshot(double sim_time, double received, std::uint16_t qx, float player_x) {
  auto s = std::make_shared<Snapshot>();
  s->sim_time = sim_time;
  s->received = received;
  s->ball_count = 1;
  s->quantised = {qx, 0, 65535};
  s->kinds = std::make_shared<std::vector<std::uint8_t>>(std::vector<std::uint8_t>{2});
  s->players = {{7, {player_x, 20.0f, 0.0f}}};
  return s;
}

}  // namespace

TEST_CASE("positions are blended between the pair and dequantised over the tank") {
  RenderPair pair{snapshot(0.0, 0.0, 0, -2.0f), snapshot(0.1, 0.1, 65535, 2.0f), 0.25f};
  std::vector<SphereInstance> out;
  const int own = interpolate(pair, info_with_player(7), out);
  REQUIRE(out.size() == 2);
  CHECK(out[0].x == Approx(-20.0f + 0.25f * 40.0f));  // a quarter of the way across the tank
  CHECK(out[0].y == Approx(0.0f));
  CHECK(out[0].z == Approx(20.0f));
  CHECK(out[0].radius == Approx(1.5f));  // kind 2: diameter 3
  CHECK(out[0].rgba[2] == kBallKinds[2].rgb[2]);
  CHECK(own == 1);
  CHECK(out[1].x == Approx(-1.0f));
  CHECK(out[1].radius == Approx(0.5f));
  CHECK(out[1].rgba == std::array<std::uint8_t, 4>{255, 255, 255, 255});  // players are white
}

TEST_CASE("a ball that is new in the later snapshot appears where it is, and others' players are not ours") {
  auto a = snapshot(0.0, 0.0, 0, 0.0f);
  auto b = snapshot(0.1, 0.1, 0, 0.0f);
  b->ball_count = 2;
  b->quantised = {0, 0, 0, 65535, 65535, 0};
  b->kinds = std::make_shared<std::vector<std::uint8_t>>(std::vector<std::uint8_t>{2, 0});
  std::vector<SphereInstance> out;
  const int own = interpolate({a, b, 0.5f}, info_with_player(3), out);
  REQUIRE(out.size() == 3);
  CHECK(out[1].x == Approx(20.0f));
  CHECK(out[1].radius == Approx(0.5f));
  CHECK(own == -1);
}

TEST_CASE("the render clock runs a little behind the newest snapshot and moves smoothly between snapshots") {
  SnapshotBuffer buffer;
  RenderPair pair;
  CHECK_FALSE(buffer.frame_at(0.0, pair));
  // Snapshots every 50 ms of server time, each arriving 10 ms after it was taken.
  for (int i = 0; i <= 20; ++i) buffer.push(snapshot(0.05 * i, 100.0 + 0.05 * i + 0.01, 0, 0.0f));
  const double delay = buffer.render_delay();
  CHECK(delay == Approx(0.075).margin(1e-6));  // 1.5 snapshot intervals

  // Frames at 144 Hz: server time shown grows by the frame time, never jumps.
  double last_shown = -1.0;
  for (double now = 100.9; now < 101.0; now += 1.0 / 144.0) {
    REQUIRE(buffer.frame_at(now, pair));
    REQUIRE(pair.to->sim_time - pair.from->sim_time == Approx(0.05));
    const double shown = pair.from->sim_time + pair.alpha * 0.05;
    CHECK(shown == Approx(now - 100.01 - delay).margin(1e-5));
    if (last_shown >= 0.0) CHECK(shown - last_shown == Approx(1.0 / 144.0).margin(1e-5));
    last_shown = shown;
  }
}

TEST_CASE("past the newest snapshot the frame holds it rather than guessing") {
  SnapshotBuffer buffer;
  buffer.push(snapshot(0.0, 10.0, 0, 0.0f));
  buffer.push(snapshot(0.05, 10.05, 65535, 0.0f));
  RenderPair pair;
  REQUIRE(buffer.frame_at(20.0, pair));  // the server went silent long ago
  CHECK(pair.from == pair.to);
  CHECK(pair.to->sim_time == 0.05);
  buffer.clear();
  CHECK_FALSE(buffer.frame_at(20.0, pair));
}

TEST_CASE("positions are dequantised over the snapshot's own tank, which follows the scene") {
  auto a = snapshot(0.0, 0.0, 65535, 0.0f);
  auto b = snapshot(0.1, 0.1, 65535, 0.0f);
  for (auto* s : {a.get(), b.get()})
    s->tank = {{-60.0f, 0.0f, -60.0f}, {60.0f, 40.0f, 60.0f}};  // a wide scene
  std::vector<SphereInstance> out;
  interpolate({a, b, 0.5f}, info_with_player(7), out);
  CHECK(out[0].x == Approx(60.0f));
  CHECK(out[0].z == Approx(60.0f));
}
