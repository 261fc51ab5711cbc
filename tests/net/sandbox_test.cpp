// The sandbox's controls against a real server: pause, step, reset, scene and
// time scale do what they say for everyone; bad values, a Step while running
// and commands the policy refuses each get an Error to the sender alone; no
// connection drops. fishtank-client's flags drive the same controls.

#include <catch2/catch.hpp>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "client/connection.h"
#include "client/script.h"
#include "clients.h"
#include "protocol/frame_codec.h"
#include "server_process.h"

using namespace fishtank;
using client::Connection;
using test::Clients;
using test::errors_with;
using test::ServerProcess;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;
namespace asio = boost::asio;

TEST_CASE("a paused server keeps sending snapshots without stepping, Step runs exactly that many, resume runs on",
          "[net][sandbox]") {
  ServerProcess server({"--balls", "200"});
  Clients clients(server.port());
  auto player = clients.add_watching(true);
  player->send(protocol::encode_pause(true));
  REQUIRE(clients.wait_until([&] { return player->view().paused; }));
  clients.run_for(milliseconds(100));
  const std::uint32_t frozen = player->view().physics_steps;
  const std::uint64_t snapshots = player->stats().snapshots;
  clients.run_for(milliseconds(400));
  CHECK(player->view().physics_steps == frozen);
  CHECK(player->stats().snapshots > snapshots + 10);  // 60 a second, paused or not

  player->send(protocol::encode_step(50));
  CHECK(clients.wait_until([&] { return player->view().physics_steps == frozen + 50; }));
  clients.run_for(milliseconds(300));
  CHECK(player->view().physics_steps == frozen + 50);
  CHECK(player->view().paused);

  player->send(protocol::encode_pause(false));
  CHECK(clients.wait_until([&] { return player->view().physics_steps > frozen + 200; }));
  CHECK_FALSE(player->view().paused);
  CHECK(player->stats().errors.empty());
}

TEST_CASE(
    "a Step while running, an unknown scene and a time scale out of range each get an Error to the sender "
    "only, and nobody's connection drops",
    "[net][sandbox]") {
  ServerProcess server({"--balls", "200"});
  Clients clients(server.port());
  auto sender = clients.add_watching(true);
  auto other = clients.add_watching(true);
  sender->send(protocol::encode_step(10));
  sender->send(protocol::encode_reset("cube", std::nullopt));
  sender->send(protocol::encode_set_time_scale(5.0f));
  sender->send(protocol::encode_set_time_scale(0.01f));
  REQUIRE(clients.wait_until([&] { return sender->stats().errors.size() >= 4; }));
  CHECK(errors_with(*sender, "not_paused") == 1);
  CHECK(errors_with(*sender, "invalid_value") == 3);
  bool names_scenes = false;
  for (const std::string& e : sender->stats().errors)
    names_scenes |= e.find("unknown scene 'cube'; the scenes are tank, wide, dam-break and drop") != std::string::npos;
  CHECK(names_scenes);
  const std::uint64_t seen = other->stats().snapshots;
  clients.run_for(milliseconds(300));
  CHECK(other->stats().errors.empty());
  CHECK(other->stats().snapshots > seen);
  CHECK_FALSE(sender->closed());
  CHECK_FALSE(other->closed());
  CHECK(sender->view().scene == "tank");  // nothing changed
  CHECK(sender->view().time_scale_set == 1.0f);
}

TEST_CASE(
    "observers may not pause or reset by default: their refusal is theirs alone, and a player's reset to another "
    "scene reaches everyone, with new ids, kinds and tank",
    "[net][sandbox]") {
  ServerProcess server({"--balls", "300"});
  Clients clients(server.port());
  auto observer = clients.add_watching(false);
  auto player = clients.add_watching(true);
  CHECK_FALSE(observer->may_control());
  CHECK(player->may_control());
  CHECK(observer->control_policy().find("observers may not") != std::string::npos);

  observer->send(protocol::encode_pause(true));
  observer->send(protocol::encode_reset("drop", std::nullopt));
  REQUIRE(clients.wait_until([&] { return errors_with(*observer, "not_permitted") == 2; }));
  clients.run_for(milliseconds(200));
  CHECK_FALSE(player->view().paused);
  CHECK(player->view().scene == "tank");
  CHECK(player->stats().errors.empty());

  const std::uint32_t start = player->view().scene_start;
  player->send(protocol::encode_reset("wide", 5));
  for (auto* c : {observer.get(), player.get()}) {
    REQUIRE(clients.wait_until([&] { return c->view().scene == "wide" && c->view().ball_count == 300; }));
    CHECK(c->view().scene_start == start + 1);
    CHECK(c->view().kinds.size() == 300);  // kinds sent again from ball 0
    CHECK(c->tank().size().x < 40.0f);     // 300 balls need a narrower tank than the 40-unit one
    // Every ball within the new tank: positions are read with the snapshot's bounds.
    float lowest = 1e9f;
    for (std::uint32_t b = 0; b < 300; ++b) lowest = std::min(lowest, c->ball_position(b).x);
    CHECK(lowest >= c->tank().min.x);
    CHECK_FALSE(c->closed());
  }
  CHECK(player->stats().errors.empty());
}

TEST_CASE("a time scale of 0.5 runs simulated time at half the wall clock's pace, and says it was asked for",
          "[net][sandbox]") {
  ServerProcess server({"--balls", "100", "--status-interval", "0.25"});
  Clients clients(server.port());
  auto player = clients.add_watching(true);
  player->send(protocol::encode_set_time_scale(0.5f));
  REQUIRE(clients.wait_until([&] { return player->view().time_scale_set == 0.5f; }));
  clients.run_for(milliseconds(600));  // a status interval or two at the new pace
  const double sim_before = player->view().sim_time;
  const Clock::time_point wall_before = Clock::now();
  clients.run_for(milliseconds(1500));
  const double ratio =
      (player->view().sim_time - sim_before) / std::chrono::duration<double>(Clock::now() - wall_before).count();
  CHECK(ratio == Approx(0.5).margin(0.08));
  CHECK(player->view().time_scale == Approx(0.5).margin(0.08));
}

TEST_CASE("with --control nobody even a player's pause is refused", "[net][sandbox]") {
  ServerProcess server({"--balls", "50", "--control", "nobody"});
  Clients clients(server.port());
  auto player = clients.add_watching(true);
  CHECK_FALSE(player->may_control());
  player->send(protocol::encode_pause(true));
  REQUIRE(clients.wait_until([&] { return errors_with(*player, "not_permitted") == 1; }));
  clients.run_for(milliseconds(200));
  CHECK_FALSE(player->view().paused);
}

TEST_CASE(
    "fishtank-client's control flags switch scene, pause and step, and a Step on a running server is refused "
    "without a drop",
    "[net][sandbox]") {
  ServerProcess server({"--balls", "300"});
  client::Script script;
  script.port = server.port();
  script.duration = 1.5;
  script.scene = "dam-break";
  script.seed = 2;
  script.pause = true;
  script.step = 100;
  const client::Summary paused = client::run_script(script);
  CHECK(paused.error_messages.empty());
  CHECK(paused.scene == "dam-break");
  CHECK(paused.scene_start == 2);
  CHECK(paused.paused);
  CHECK(paused.balls == 300);

  client::Script running;
  running.port = server.port();
  running.duration = 1.0;
  running.pause = false;
  running.time_scale = 0.5f;
  running.step = 10;  // after the resume: the server runs, so Step is refused
  const client::Summary refused = client::run_script(running);
  CHECK(refused.dropped == 0);
  REQUIRE(refused.error_messages.size() == 1);
  CHECK(refused.error_messages[0].rfind("not_paused:", 0) == 0);
  CHECK_FALSE(refused.paused);
  CHECK(refused.time_scale_set == 0.5);
}

TEST_CASE("a burst of resets is coalesced, any refused only as server busy, and the snapshots of others do not stall",
          "[net][sandbox]") {
  // 3000 balls placed at each start; the command-flood limit is raised above the burst, which is not its subject.
  ServerProcess server({"--scene", "dam-break", "--max-commands", "1000"});
  Clients clients(server.port());
  auto sender = clients.add_watching(true);
  auto other = clients.add_watching(false);
  const std::uint32_t start = sender->view().scene_start;
  for (int i = 0; i < 300; ++i) sender->send(protocol::encode_reset("", i));
  const std::uint64_t seen = other->stats().snapshots;
  clients.run_for(milliseconds(1500));
  INFO("scene starts " << sender->view().scene_start - start);
  CHECK(sender->view().scene_start > start);
  CHECK(sender->view().scene_start - start < 300);  // bursts coalesced
  CHECK(other->stats().snapshots - seen >= 45);     // 60 a second, nearly undisturbed
  CHECK(other->stats().errors.empty());
  // Refusals, if any fell between restarts, are all server_busy (physics_link_test: a reset too soon).
  CHECK(errors_with(*sender, "server_busy") == static_cast<int>(sender->stats().errors.size()));
}
