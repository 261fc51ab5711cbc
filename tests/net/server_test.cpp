// fishtank-server as a daemon: a real server process on an ephemeral
// 127.0.0.1 port, real TCP clients. Each test names the fact it checks; every
// wait is bounded, so a broken server fails a test instead of hanging it.

#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "client/connection.h"
#include "client/script.h"
#include "clients.h"
#include "protocol/frame_codec.h"
#include "server_process.h"
#include "wire_bytes.h"

using namespace fishtank;
using client::Connection;
using test::Clients;
using test::error_codes;
using test::first_error_code;
using test::frame_with_length;
using test::has_error;
using test::measure_rates;
using test::RawSocket;
using test::ServerProcess;
using test::wait_until;
using Clock = std::chrono::steady_clock;

namespace {

// The server's status lines ("t = ... s  balls ..."), oldest first.
std::vector<std::string> status_lines(const ServerProcess& server) {
  std::vector<std::string> lines;
  std::istringstream log(server.log());
  for (std::string line; std::getline(log, line);)
    if (line.rfind("t = ", 0) == 0) lines.push_back(line);
  return lines;
}

// The status line of a window in which no snapshot was captured and no frame coded.
bool codes_nothing(const std::string& status) {
  return status.find("snapshot 0 us to encode, 0.00 frames of 0 B mean, 0 keyframes") != std::string::npos;
}

}  // namespace

TEST_CASE(
    "several clients each receive snapshots at the snapshot rate, and on SIGTERM each is told why it ends and "
    "the server stops cleanly",
    "[net]") {
  ServerProcess server({"--balls", "500", "--snapshot-rate", "60"});
  Clients clients(server.port());
  std::vector<std::shared_ptr<Connection>> all;
  for (int i = 0; i < 4; ++i) all.push_back(clients.add(/*wants_player=*/i % 2 == 0));
  REQUIRE(clients.wait_until([&] { return clients.all_welcomed(); }, std::chrono::seconds(5)));
  clients.run_for(std::chrono::milliseconds(200));
  for (double rate : measure_rates(clients, all, 1.5)) {
    CHECK(rate > 45.0);  // 60 Hz asked; generous for a loaded 2-core machine
    CHECK(rate < 70.0);
  }
  for (auto& c : all) {
    CHECK(c->stats().errors.empty());
    CHECK(c->view().ball_count > 0);
    CHECK(c->view().kinds.size() >= c->view().ball_count);       // every ball's kind arrived before the ball
    CHECK(c->stats().kinds_received == c->view().kinds.size());  // and once: a ball's size is not sent again
  }
  CHECK(all[0]->player_id().has_value());
  CHECK_FALSE(all[1]->player_id().has_value());  // observers get no sphere

  server.request_stop();
  REQUIRE(
      clients.wait_until([&] { return std::all_of(all.begin(), all.end(), [](const auto& c) { return c->closed(); }); },
                         std::chrono::seconds(5)));
  for (auto& c : all) {
    CHECK(has_error(*c, "server_stopping"));
    CHECK_THAT(c->close_reason(), Catch::Contains("the server is stopping: it was stopped"));
  }
  CHECK(server.terminate() == 0);
}

TEST_CASE("a client that neither reads nor closes does not hold a stopping server past its grace", "[net]") {
  ServerProcess server({"--balls", "0"});
  RawSocket stalled(server.port());
  stalled.send(protocol::encode_hello("stalled", false, false));
  REQUIRE(server.wait_for_log("welcomed", std::chrono::seconds(5)));
  server.request_stop();
  CHECK(server.terminate() == 0);  // -1: it was still running 10 s later
  CHECK_THAT(server.log(), Catch::Contains("closed: disconnected by the server; the client had not closed its side"));
  // What it was sent ends with the Error saying why.
  std::vector<std::uint8_t> received;
  REQUIRE(stalled.read_until_closed(received, std::chrono::seconds(5)));
  const std::string text(received.begin(), received.end());
  CHECK_THAT(text, Catch::Contains("the server is stopping"));
}

TEST_CASE("every snapshot says how many threads step, at most Welcome's worker threads, and how fast time runs",
          "[net]") {
  ServerProcess server({"--balls", "500", "--threads", "2", "--status-interval", "0.5"});
  Clients clients(server.port());
  auto c = clients.add(false);
  REQUIRE(clients.wait_until([&] { return c->welcomed(); }, std::chrono::seconds(5)));
  CHECK(c->worker_threads() == 2);
  // Past two status intervals, so the figures are measured ones.
  clients.run_for(std::chrono::milliseconds(1200));
  REQUIRE(c->stats().snapshots > 0);

  const Clock::time_point start = Clock::now();
  const double sim_start = c->view().sim_time;
  std::uint32_t tick = c->view().tick;
  int seen = 0;
  double scale_sum = 0.0;
  while (Clock::now() - start < std::chrono::milliseconds(1500)) {
    clients.run_for(std::chrono::milliseconds(10));
    const client::WorldView& v = c->view();
    if (v.tick == tick) continue;
    tick = v.tick;
    ++seen;
    scale_sum += v.time_scale;
    INFO("snapshot " << v.tick << ": " << v.threads_stepping << " threads stepping, time scale " << v.time_scale);
    CHECK(v.threads_stepping >= 1);
    CHECK(v.threads_stepping <= c->worker_threads());
    CHECK(v.time_scale > 0.0f);
    CHECK(v.time_scale <= 1.05f);
  }
  REQUIRE(seen > 10);
  // What the server reports is what a client sees: simulated seconds per wall second.
  const double observed =
      (c->view().sim_time - sim_start) / std::chrono::duration<double>(Clock::now() - start).count();
  CHECK(scale_sum / seen == Approx(observed).margin(0.25));
}

TEST_CASE("more threads than cores are allowed, and the server says they are oversubscribed", "[net]") {
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const std::string threads = std::to_string(std::max(8u, 2 * cores));
  ServerProcess server({"--balls", "0", "--threads", threads});
  Clients clients(server.port());
  auto c = clients.add(false);
  REQUIRE(clients.wait_until([&] { return c->stats().snapshots > 0; }, std::chrono::seconds(5)));
  CHECK(std::to_string(c->worker_threads()) == threads);
  CHECK_THAT(server.log(), Catch::Contains(threads + " threads on ") && Catch::Contains(": oversubscribed"));
}

TEST_CASE("AddBalls raises the ball count that every client sees - beyond room it gets an Error saying why", "[net]") {
  ServerProcess server({"--balls", "0", "--max-balls", "300"});
  Clients clients(server.port());
  auto adder = clients.add(true);  // players may add balls (--add-rights players)
  auto watcher1 = clients.add(false);
  auto watcher2 = clients.add(true);
  REQUIRE(clients.wait_until([&] { return clients.all_welcomed(); }, std::chrono::seconds(5)));
  REQUIRE(clients.wait_until([&] { return watcher1->stats().snapshots > 0; }, std::chrono::seconds(5)));
  CHECK(watcher1->view().ball_count == 0);

  adder->send(protocol::encode_add_balls(200));
  const auto all_see = [&](std::uint32_t n) {
    return adder->view().ball_count >= n && watcher1->view().ball_count >= n && watcher2->view().ball_count >= n;
  };
  CHECK(clients.wait_until([&] { return all_see(200); }, std::chrono::seconds(10)));
  CHECK(adder->stats().errors.empty());

  adder->send(protocol::encode_add_balls(500));  // only 100 more fit under --max-balls 300
  REQUIRE(clients.wait_until([&] { return !adder->stats().errors.empty(); }, std::chrono::seconds(5)));
  CHECK(has_error(*adder, "tank_full"));
  CHECK_THAT(adder->stats().errors.front(), Catch::Contains("100"));
  CHECK(clients.wait_until([&] { return all_see(300); }, std::chrono::seconds(10)));
  CHECK(watcher1->view().kinds.size() >= 300);
  CHECK(watcher1->stats().errors.empty());
}

TEST_CASE("PlayerInput moves that client's sphere which pushes the balls it touches - leaving removes it", "[net]") {
  ServerProcess server({"--balls", "400"});
  Clients clients(server.port());
  auto player = clients.add(true);
  auto observer = clients.add(false);
  REQUIRE(clients.wait_until([&] { return clients.all_welcomed(); }, std::chrono::seconds(5)));
  REQUIRE(player->player_id());
  const std::uint32_t id = *player->player_id();
  REQUIRE(clients.wait_until([&] { return observer->view().ball_count == 400; }, std::chrono::seconds(10)));

  const auto positions = [&] {
    std::vector<Vec3> p;
    for (std::uint32_t b = 0; b < observer->view().ball_count; ++b) p.push_back(observer->ball_position(b));
    return p;
  };
  const auto moved_more_than = [](const std::vector<Vec3>& a, const std::vector<Vec3>& b, float d) {
    int n = 0;
    for (std::size_t i = 0; i < a.size(); ++i) n += length(a[i] - b[i]) > d;
    return n;
  };
  // Control: wait until the pile is at rest, i.e. while the sphere stands
  // still at most two balls move more than 0.3 units in half a second (with
  // no friction, a ball can glide on the floor for many seconds).
  std::vector<Vec3> rest = positions();
  bool settled = false;
  for (int tries = 0; tries < 40 && !settled; ++tries) {
    clients.run_for(std::chrono::milliseconds(500));
    std::vector<Vec3> now = positions();
    settled = moved_more_than(rest, now, 0.3f) <= 2;
    rest = std::move(now);
  }
  REQUIRE(settled);

  const Vec3 start = *observer->player_position(id);
  player->send(protocol::encode_player_input(1, {0.0f, -10.0f, 0.0f}));  // down into the pile...
  clients.run_for(std::chrono::milliseconds(2200));
  const Vec3 low = *observer->player_position(id);
  CHECK(low.y < start.y - 10.0f);
  player->send(protocol::encode_player_input(2, {10.0f, 0.0f, 0.0f}));  // ...and through it along +x
  clients.run_for(std::chrono::milliseconds(1200));
  player->send(protocol::encode_player_input(3, {0.0f, 0.0f, 0.0f}));
  clients.run_for(std::chrono::milliseconds(200));
  const Vec3 end = *observer->player_position(id);
  CHECK(end.x > low.x + 8.0f);
  INFO("balls moved by the sweep: " << moved_more_than(rest, positions(), 0.3f));
  CHECK(moved_more_than(rest, positions(), 0.3f) >= 10);  // the sweep, not the gliders
  CHECK(player->stats().errors.empty());

  player->close();
  CHECK(clients.wait_until([&] { return !observer->player_position(id); }, std::chrono::seconds(5)));
}

TEST_CASE("NaN and infinite input gets an Error and is ignored - the connection stays", "[net]") {
  ServerProcess server({"--balls", "0"});
  Clients clients(server.port());
  auto player = clients.add(true);
  REQUIRE(clients.wait_until([&] { return player->welcomed(); }, std::chrono::seconds(5)));
  player->send(protocol::encode_player_input(1, {std::nanf(""), 0.0f, 0.0f}));
  player->send(protocol::encode_player_input(2, {0.0f, INFINITY, 0.0f}));
  REQUIRE(clients.wait_until([&] { return player->stats().errors.size() >= 2; }, std::chrono::seconds(5)));
  CHECK(has_error(*player, "invalid_value"));
  const std::uint64_t before = player->stats().snapshots;
  clients.run_for(std::chrono::milliseconds(300));
  CHECK(player->stats().snapshots > before);
  CHECK_FALSE(player->closed());
  const Vec3 p = *player->player_position(*player->player_id());
  CHECK(is_finite(p));
}

TEST_CASE("a protocol version mismatch is refused with a clear Error and a disconnect", "[net]") {
  ServerProcess server({"--balls", "0"});
  Clients clients(server.port());
  auto old_client = clients.add(true, protocol::kProtocolVersion + 41);
  REQUIRE(clients.wait_until([&] { return old_client->closed(); }, std::chrono::seconds(5)));
  CHECK_FALSE(old_client->welcomed());
  REQUIRE(has_error(*old_client, "version_mismatch"));
  CHECK_THAT(old_client->stats().errors.front(), Catch::Contains("protocol version"));
}

TEST_CASE("a client that says Watching off gets no snapshots but its replies, and on again gets deltas it decodes",
          "[net]") {
  ServerProcess server({"--balls", "300"});
  Clients clients(server.port());
  auto hidden = clients.add(true);
  REQUIRE(clients.wait_until([&] { return hidden->stats().snapshots > 10; }, std::chrono::seconds(5)));
  hidden->send(protocol::encode_watching(false));
  // Snapshots already on their way still arrive: wait for a quiet 300 ms (a busy machine may take longer).
  bool quiet = false;
  for (int tries = 0; tries < 20 && !quiet; ++tries) {
    const std::uint64_t seen = hidden->stats().snapshots;
    clients.run_for(std::chrono::milliseconds(300));
    quiet = hidden->stats().snapshots == seen;
  }
  REQUIRE(quiet);
  const std::uint64_t before = hidden->stats().snapshots;
  const std::size_t pongs = hidden->stats().rtt_ms.size();
  hidden->send_ping();
  clients.run_for(std::chrono::milliseconds(1000));
  CHECK(hidden->stats().snapshots == before);
  CHECK(hidden->stats().rtt_ms.size() == pongs + 1);  // replies still come
  CHECK_FALSE(hidden->closed());

  hidden->send(protocol::encode_watching(true));
  const std::uint64_t keyframes = hidden->stats().keyframes;
  REQUIRE(clients.wait_until([&] { return hidden->stats().snapshots > before + 30; }, std::chrono::seconds(5)));
  // A delta against its base, or one keyframe where the base left the server's kept ones while it watched nothing.
  CHECK(hidden->stats().keyframes <= keyframes + 1);
  CHECK(hidden->stats().errors.empty());
  CHECK(hidden->view().ball_count > 0);
}

TEST_CASE("bad bytes from one client: Error and disconnect for it - the server and other clients carry on", "[net]") {
  ServerProcess server({"--balls", "300"});
  Clients clients(server.port());
  auto watcher = clients.add(false);
  REQUIRE(clients.wait_until([&] { return watcher->stats().snapshots > 5; }, std::chrono::seconds(5)));
  const long rss_before = server.rss_kb();

  SECTION("a browser's HTTP request: an HTTP 400 that says this port is not the browser viewer's, then the end") {
    RawSocket raw(server.port());
    raw.send_text("GET / HTTP/1.1\r\nHost: x\r\n\r\n");
    std::vector<std::uint8_t> got;
    CHECK(raw.read_until_closed(got, std::chrono::seconds(5)));
    const std::string text(got.begin(), got.end());
    CHECK(text.rfind("HTTP/1.1 400 Bad Request\r\n", 0) == 0);
    // This server serves no page (--no-web): the answer says so rather than naming a port.
    CHECK_THAT(text, Catch::Contains("This server serves no browser viewer (it was started with --no-web)."));
  }
  SECTION("garbage: a plausible length followed by random bytes") {
    RawSocket raw(server.port());
    raw.send(frame_with_length(64, 64));
    std::vector<std::uint8_t> got;
    CHECK(raw.read_until_closed(got, std::chrono::seconds(5)));
    CHECK(first_error_code(got) == "malformed_frame");
  }
  SECTION("an oversized length prefix (2 GiB) is refused without allocating it") {
    RawSocket raw(server.port());
    raw.send(frame_with_length(0x7fffffffu, 16));
    std::vector<std::uint8_t> got;
    CHECK(raw.read_until_closed(got, std::chrono::seconds(5)));
    CHECK(first_error_code(got) == "malformed_frame");
    CHECK(server.rss_kb() < rss_before + 50 * 1024);
  }
  SECTION("a valid frame before Hello is refused") {
    RawSocket raw(server.port());
    raw.send(protocol::encode_ping(1));
    std::vector<std::uint8_t> got;
    CHECK(raw.read_until_closed(got, std::chrono::seconds(5)));
    CHECK(first_error_code(got) == "expected_hello");
  }
  SECTION("a Hello and garbage in one write: the Error is the last word, and the log says why the connection ended") {
    RawSocket raw(server.port());
    protocol::Frame bytes = protocol::encode_hello("hello-then-garbage", true, false);
    const protocol::Frame garbage = frame_with_length(64, 64);
    bytes.insert(bytes.end(), garbage.begin(), garbage.end());
    raw.send(bytes);
    std::vector<std::uint8_t> got;
    CHECK(raw.read_until_closed(got, std::chrono::seconds(5)));
    CHECK(error_codes(got) == std::vector<std::string>{"malformed_frame"});
    // The socket kept open, the server waits out its grace: the physics thread's Welcome for the
    // Hello comes meanwhile, and is not written after the farewell (a write there failed: "Broken pipe").
    REQUIRE(server.wait_for_log("('hello-then-garbage') closed: ", std::chrono::seconds(5)));
    CHECK_THAT(server.log(), Catch::Contains("('hello-then-garbage') closed: disconnected by the server"));
  }
  SECTION("half a frame, then the client disconnects") {
    RawSocket raw(server.port());
    const protocol::Frame hello = protocol::encode_hello("half", true, false);
    raw.send(protocol::Frame(hello.begin(), hello.begin() + static_cast<long>(hello.size() / 2)));
    clients.run_for(std::chrono::milliseconds(100));
    raw.close();
  }

  // The watcher kept receiving at its rate, and the server is up and accepts newcomers.
  const double rate = measure_rates(clients, {watcher}, 1.0).front();
  CHECK(rate > 45.0);
  CHECK(server.running());
  auto newcomer = clients.add(true);
  CHECK(clients.wait_until([&] { return newcomer->stats().snapshots > 0; }, std::chrono::seconds(5)));
  CHECK(watcher->stats().errors.empty());
}

TEST_CASE("physics far over its real-time budget: observers keep their snapshot rate and are told of slow motion",
          "[net]") {
  // Stiff contacts resolved over 100 steps make dt tiny: real time would need
  // several times the steps per second one thread runs.
  ServerProcess server({"--balls", "2000", "--stiffness", "1e9", "--steps-per-contact", "100"});
  Clients clients(server.port());
  auto observer = clients.add(false);
  REQUIRE(clients.wait_until([&] { return observer->view().ball_count > 500; }, std::chrono::seconds(15)));
  clients.run_for(std::chrono::milliseconds(1500));  // a status interval: the time scale is measured
  const double rate = measure_rates(clients, {observer}, 2.0).front();
  CHECK(rate >= 30.0);  // 60 Hz asked; before the budget, about one a second
  const float scale = observer->view().time_scale;
  CHECK(scale > 0.0f);
  CHECK(scale < 0.9f);
  CHECK(server.running());
}

TEST_CASE("a client the server drops says so and stops, instead of waiting out its duration", "[net]") {
  ServerProcess server({"--balls", "100"});
  client::Script script;
  script.port = server.port();
  script.observer = true;
  script.duration = 20.0;
  client::Summary summary;
  std::thread run([&] { summary = client::run_script(script); });
  // Dropped once welcomed: the server logs the Welcome as it sends it, then the client has a second to read it.
  const bool welcomed = server.wait_for_log("welcomed as observer", std::chrono::seconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  const auto dropped_at = std::chrono::steady_clock::now();
  server.terminate();
  run.join();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - dropped_at).count();
  REQUIRE(welcomed);
  CHECK(summary.welcomed == 1);
  CHECK(summary.dropped == 1);
  CHECK(seconds < 10.0);  // not the rest of the 20 s asked
  REQUIRE_FALSE(summary.error_messages.empty());
  CHECK(summary.error_messages.back().find("dropped by the server") != std::string::npos);
}

TEST_CASE("a client that acknowledges gets deltas that decode to the positions a client without Acks gets in full",
          "[net][delta]") {
  ServerProcess server({"--balls", "600"});  // pouring: most balls move
  Clients clients(server.port());
  auto acking = clients.add(false);
  auto full = clients.add(false);
  full->acknowledge_snapshots(false);
  int compared = 0;
  for (int round = 0; round < 20; ++round) {
    // Both read each snapshot within a few milliseconds: wait until they hold the same one.
    const std::uint32_t after = acking->view().tick;
    REQUIRE(clients.wait_until([&] { return acking->view().tick > after && acking->view().tick == full->view().tick; },
                               std::chrono::seconds(5)));
    CHECK(acking->view().positions == full->view().positions);
    ++compared;
    clients.run_for(std::chrono::milliseconds(100));
  }
  CHECK(compared == 20);
  // On joining only (and while the first Ack is on its way, on a busy machine).
  CHECK(acking->stats().keyframes <= 3);
  CHECK(full->stats().keyframes == full->stats().snapshots);
  CHECK(acking->stats().bytes_received < full->stats().bytes_received);
  CHECK(acking->stats().errors.empty());
}

TEST_CASE("Acks that cannot be true get an Error and a keyframe, and the connection and other clients go on",
          "[net][delta]") {
  ServerProcess server({"--balls", "300"});
  Clients clients(server.port());
  auto liar = clients.add(false);
  auto other = clients.add(false);
  REQUIRE(clients.wait_until([&] { return liar->stats().snapshots > 5 && other->stats().snapshots > 5; },
                             std::chrono::seconds(5)));
  const std::uint64_t keyframes = liar->stats().keyframes, others_keyframes = other->stats().keyframes;
  liar->send(protocol::encode_ack(liar->view().tick + 1000));  // a snapshot not sent yet
  REQUIRE(clients.wait_until([&] { return has_error(*liar, "invalid_value"); }, std::chrono::seconds(5)));
  CHECK_THAT(liar->stats().errors.back(), Catch::Contains("not been sent yet"));
  REQUIRE(clients.wait_until([&] { return liar->stats().keyframes > keyframes; }, std::chrono::seconds(5)));
  liar->send(protocol::encode_ack(liar->view().tick, /*want_keyframe=*/true));
  REQUIRE(clients.wait_until([&] { return liar->stats().keyframes > keyframes + 1; }, std::chrono::seconds(5)));

  const std::uint64_t seen = liar->stats().snapshots;
  clients.run_for(std::chrono::milliseconds(300));
  CHECK(liar->stats().snapshots > seen);  // still connected, deltas again
  CHECK_FALSE(liar->closed());
  CHECK(other->stats().errors.empty());
  CHECK(other->stats().keyframes == others_keyframes);
  CHECK(server.running());
}

TEST_CASE("fishtank-client --clients 60 on a server's default limits gets all 60 welcomed, none evicted as pending",
          "[net]") {
  // Opened all at once, most of them waited for their Hello to be read beyond --max-pending-per-address (8) and
  // were evicted as a stranger's stalled connections: 8 of 60 welcomed.
  ServerProcess server({"--balls", "100"});
  client::Script script;
  script.port = server.port();
  script.clients = 60;
  script.observer = true;
  script.duration = 1.5;
  const client::Summary summary = client::run_script(script);
  CHECK(summary.welcomed == 60);
  CHECK(summary.error_messages.empty());
  CHECK(summary.snapshots > 60 * 30);  // every connection received snapshots for most of the 1.5 s
  // A mean of each connection's rate over the span it received snapshots: about the server's 60 a second.
  CHECK(summary.snapshot_rate_hz > 30.0);
  CHECK(summary.snapshot_rate_hz < 70.0);
}

TEST_CASE("fishtank-client stops at --duration with connections still unopened, and says how many", "[net]") {
  ServerProcess server({"--balls", "100"});
  client::Script script;
  script.port = server.port();
  script.clients = 500;
  script.max_pending = 1;  // one Welcome at a time: 500 cannot all open in 0.3 s
  script.observer = true;
  script.duration = 0.3;
  const auto start = std::chrono::steady_clock::now();
  const client::Summary summary = client::run_script(script);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(seconds < 5.0);  // a ramp tick due at the end once opened the rest, which then ran on forever
  CHECK(summary.welcomed < 500);
  CHECK(std::any_of(summary.error_messages.begin(), summary.error_messages.end(), [](const std::string& e) {
    return e.find("connections not opened: --duration ended") != std::string::npos;
  }));
}

TEST_CASE("no snapshot is captured or coded while nobody watches, and none once the last viewer has left", "[net]") {
  ServerProcess server({"--balls", "300", "--status-interval", "0.25"});
  REQUIRE(wait_until([&] { return status_lines(server).size() >= 4; }, std::chrono::seconds(10)));
  for (const std::string& line : status_lines(server)) CHECK(codes_nothing(line));

  Clients clients(server.port());
  auto watcher = clients.add(false);
  REQUIRE(clients.wait_until([&] { return watcher->stats().snapshots > 10; }, std::chrono::seconds(10)));
  REQUIRE(wait_until([&] { return !codes_nothing(status_lines(server).back()); }, std::chrono::seconds(5)));

  watcher->close();
  REQUIRE(server.wait_for_log(") closed: ", std::chrono::seconds(5)));
  const std::size_t after_leaving = status_lines(server).size();
  // The window the viewer left in may have coded some; the two after it code none.
  REQUIRE(wait_until([&] { return status_lines(server).size() >= after_leaving + 3; }, std::chrono::seconds(10)));
  const std::vector<std::string> lines = status_lines(server);
  CHECK(codes_nothing(lines[lines.size() - 1]));
  CHECK(codes_nothing(lines[lines.size() - 2]));
}
