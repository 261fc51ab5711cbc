// Player spheres on a real server: more clients than spheres wait in line and
// get freed ones first come first served, through any order of joins and
// leaves; a sphere freed as unmoved goes to the one in line; players who join
// together start apart.

#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "clients.h"
#include "server_process.h"

using namespace fishtank;
using client::Connection;
using test::Clients;
using test::has_error;
using test::ServerProcess;

TEST_CASE("more clients than --max-players wait in line, told so, and get freed spheres first come first served",
          "[net]") {
  ServerProcess server({"--balls", "0", "--max-players", "1"});
  Clients clients(server.port());
  auto first = clients.add(true);
  REQUIRE(clients.wait_until([&] { return first->welcomed(); }, std::chrono::seconds(5)));
  auto second = clients.add(true);
  REQUIRE(clients.wait_until([&] { return second->welcomed(); }, std::chrono::seconds(5)));
  // One at a time: two Hellos sent together may join the line in either order.
  auto third = clients.add(true);
  REQUIRE(clients.wait_until([&] { return third->welcomed(); }, std::chrono::seconds(5)));
  auto quitter = clients.add(true);
  auto observer = clients.add(false);
  REQUIRE(clients.wait_until([&] { return clients.all_welcomed(); }, std::chrono::seconds(5)));
  REQUIRE(first->player_id().has_value());
  CHECK_FALSE(second->player_id().has_value());
  REQUIRE(has_error(*second, "player_limit"));
  CHECK_THAT(second->stats().errors.front(), Catch::Contains("in line for the next one freed"));
  CHECK(observer->stats().errors.empty());  // it asked for none, so it is not in line
  CHECK_FALSE(observer->ahead_in_line().has_value());
  // Each in line knows its place.
  REQUIRE(clients.wait_until([&] { return quitter->ahead_in_line() == 2u; }, std::chrono::seconds(5)));
  CHECK(second->ahead_in_line() == 0u);
  CHECK(third->ahead_in_line() == 1u);

  // One in line that leaves gives up its place: the sphere skips it.
  quitter->close();
  clients.run_for(std::chrono::milliseconds(200));
  first->close();
  REQUIRE(clients.wait_until([&] { return second->player_id().has_value(); }, std::chrono::seconds(5)));
  CHECK(second->stats().player_granted);
  CHECK_FALSE(second->ahead_in_line().has_value());
  CHECK_FALSE(third->player_id().has_value());
  REQUIRE(clients.wait_until([&] { return third->ahead_in_line() == 0u; }, std::chrono::seconds(5)));
  CHECK(second->may_control());  // the default policy: players may control

  // The granted sphere is second's to move.
  const std::uint32_t id = *second->player_id();
  REQUIRE(clients.wait_until([&] { return observer->player_position(id).has_value(); }, std::chrono::seconds(5)));
  const Vec3 start = *observer->player_position(id);
  second->send(protocol::encode_player_input(1, {5.0f, 0.0f, 0.0f}));
  clients.run_for(std::chrono::milliseconds(600));
  second->send(protocol::encode_player_input(2, {0.0f, 0.0f, 0.0f}));
  REQUIRE(
      clients.wait_until([&] { return observer->player_position(id)->x > start.x + 1.0f; }, std::chrono::seconds(5)));

  second->close();
  REQUIRE(clients.wait_until([&] { return third->player_id().has_value(); }, std::chrono::seconds(5)));
  CHECK_FALSE(observer->player_id().has_value());
  CHECK(third->stats().errors.size() == 1);  // player_limit, and nothing since
}

TEST_CASE("through joins and leaves in any order, every sphere has one holder and none waits while one is free",
          "[net]") {
  constexpr int kMaxPlayers = 4;
  // Room for every connection opened in a burst to wait for its Welcome, none evicted as a stranger's.
  ServerProcess server(
      {"--balls", "0", "--max-players", std::to_string(kMaxPlayers), "--max-pending-per-address", "64"});
  Clients clients(server.port());
  auto watcher = clients.add(false);
  std::vector<std::shared_ptr<Connection>> live;
  std::uint32_t seed = 12345;
  const auto next_random = [&] { return seed = seed * 1664525u + 1013904223u; };
  for (int round = 0; round < 60; ++round) {
    // Mostly joins while few are connected, mostly leaves while many are: the line grows and empties.
    if (live.empty() || next_random() % 12 >= live.size())
      live.push_back(clients.add(true));
    else {
      const auto leaving = live.begin() + next_random() % live.size();
      (*leaving)->close();
      live.erase(leaving);
    }
    clients.run_for(std::chrono::milliseconds(next_random() % 30));
  }
  const auto holders = [&] {
    std::vector<std::uint32_t> ids;
    for (auto& c : live)
      if (c->player_id()) ids.push_back(*c->player_id());
    std::sort(ids.begin(), ids.end());
    return ids;
  };
  const auto spheres = [&] {
    std::vector<std::uint32_t> ids = watcher->view().player_ids;
    std::sort(ids.begin(), ids.end());
    return ids;
  };
  const std::size_t expected = std::min<std::size_t>(live.size(), kMaxPlayers);
  INFO(live.size() << " clients want a sphere at the end");
  REQUIRE(clients.wait_until([&] { return holders().size() == expected && spheres() == holders(); },
                             std::chrono::seconds(10)));
  const std::vector<std::uint32_t> held = holders();
  CHECK(std::adjacent_find(held.begin(), held.end()) == held.end());  // no sphere with two holders
  // Those in line hold the places 0, 1, 2, ... each once.
  const auto places = [&] {
    std::vector<std::uint32_t> ahead;
    for (auto& c : live)
      if (!c->player_id()) ahead.push_back(c->ahead_in_line().value_or(999));
    std::sort(ahead.begin(), ahead.end());
    return ahead;
  };
  const auto first_places = [](std::size_t n) {
    std::vector<std::uint32_t> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint32_t>(i);
    return v;
  };
  CHECK(clients.wait_until([&] { return places() == first_places(live.size() - expected); }, std::chrono::seconds(5)));
  // Closing every holder hands each sphere on down the line until the line is empty.
  while (!live.empty()) {
    auto holder = std::find_if(live.begin(), live.end(), [](auto& c) { return c->player_id().has_value(); });
    REQUIRE(holder != live.end());
    (*holder)->close();
    live.erase(holder);
    const std::size_t now_expected = std::min<std::size_t>(live.size(), kMaxPlayers);
    REQUIRE(clients.wait_until([&] { return holders().size() == now_expected && spheres() == holders(); },
                               std::chrono::seconds(10)));
    CHECK(clients.wait_until([&] { return places() == first_places(live.size() - now_expected); },
                             std::chrono::seconds(5)));
  }
  CHECK(spheres().empty());
}

TEST_CASE("a sphere freed as unmoved (player_idle) goes to the one in line, not back to its idler", "[net]") {
  // 2 s of grace: the second client must be welcomed into the line before the idler's sphere is freed.
  ServerProcess server({"--balls", "0", "--max-players", "1", "--player-idle", "2"});
  Clients clients(server.port());
  auto idler = clients.add(true);
  REQUIRE(clients.wait_until([&] { return idler->welcomed(); }, std::chrono::seconds(5)));
  auto waiting = clients.add(true);
  REQUIRE(clients.wait_until([&] { return waiting->welcomed(); }, std::chrono::seconds(5)));
  REQUIRE(idler->player_id().has_value());
  REQUIRE_FALSE(waiting->player_id().has_value());

  REQUIRE(clients.wait_until([&] { return waiting->player_id().has_value(); }, std::chrono::seconds(10)));
  CHECK(has_error(*idler, "player_idle"));
  CHECK_FALSE(idler->player_id().has_value());
  CHECK_FALSE(idler->closed());
  // The granted sphere has its own idle deadline: unmoved, it is freed in turn, and nobody waits for it.
  REQUIRE(clients.wait_until([&] { return has_error(*waiting, "player_idle"); }, std::chrono::seconds(10)));
  CHECK_FALSE(waiting->player_id().has_value());
  CHECK_FALSE(idler->player_id().has_value());
}

TEST_CASE("players who join together start apart, not as one sphere", "[net]") {
  ServerProcess server({"--balls", "0"});
  Clients clients(server.port());
  std::vector<std::shared_ptr<Connection>> players;
  for (int i = 0; i < 3; ++i) players.push_back(clients.add(true));
  REQUIRE(clients.wait_until([&] { return players[0]->view().player_ids.size() == 3; }, std::chrono::seconds(5)));
  const std::vector<Vec3>& at = players[0]->view().player_positions;
  for (std::size_t i = 0; i < at.size(); ++i)
    for (std::size_t j = 0; j < i; ++j) CHECK(length(at[i] - at[j]) >= kPlayerDiameter);
}
