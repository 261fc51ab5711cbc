// The server's side of a conversation, without sockets: a peer's name reaches
// the log only as printable text, so it cannot forge a status line.

#include "server/net/client_protocol.h"

#include <catch2/catch.hpp>
#include <memory>
#include <string>
#include <vector>

#include "common/printable_text.h"

using namespace fishtank;

TEST_CASE("a client name with a newline or an escape code is logged escaped and cut short", "[net]") {
  const net::ServerInfo info;
  net::ClientProtocol client(1, info);
  const std::string forged = "viewer\nt =    1.0 s  balls  9999\x1b[2K";
  const protocol::Frame hello = protocol::encode_hello(forged, false, false);
  client.on_frame(hello.data(), hello.size());
  const std::string& name = client.client_name();
  CHECK(name == "viewer\\x0at =    1.0 s  balls  9999\\x1b[2K");
  CHECK(name.find('\n') == std::string::npos);
  CHECK(name.find('\x1b') == std::string::npos);

  CHECK(printable_text(std::string(1000, 'a'), net::kMaxNameBytes) == std::string(net::kMaxNameBytes, 'a') + "...");
  CHECK(printable_text("back\\slash", 10) == "back\\x5cslash");  // an escape cannot be faked either
  CHECK(printable_text("caf\xc3\xa9", 10) == "caf\\xc3\\xa9");
}

TEST_CASE("before Hello a peer may announce 1 KiB at most, after it the general cap holds", "[net]") {
  const net::ServerInfo info;
  net::ClientProtocol client(1, info);
  const auto announce = [&](std::uint32_t length) {
    const std::uint8_t prefix[4] = {static_cast<std::uint8_t>(length), static_cast<std::uint8_t>(length >> 8),
                                    static_cast<std::uint8_t>(length >> 16), static_cast<std::uint8_t>(length >> 24)};
    std::uint32_t body = 0;
    return client.check_length_prefix(prefix, &body).ok();
  };
  CHECK(announce(net::kMaxFirstFrameBytes));
  CHECK_FALSE(announce(net::kMaxFirstFrameBytes + 1));
  const protocol::Frame hello = protocol::encode_hello("viewer", false, false);
  client.on_frame(hello.data(), hello.size());
  CHECK(announce(protocol::kMaxClientFrameBytes));
  CHECK_FALSE(announce(protocol::kMaxClientFrameBytes + 1));
}

TEST_CASE("a burst beyond --max-commands is a command flood, the same rate spread over time is not", "[net]") {
  net::ServerInfo info;
  info.limits.max_commands_per_s = 10.0;
  const auto t0 = net::ClientProtocol::Clock::now();
  const protocol::Frame hello = protocol::encode_hello("viewer", false, false);
  const protocol::Frame ping = protocol::encode_ping(1);

  net::ClientProtocol steady(1, info);
  steady.on_frame(hello.data(), hello.size(), t0);
  bool flooded = false;
  for (int i = 1; i <= 50; ++i)  // 50 Pings over 5 s: 10 a second
    flooded |= steady.on_frame(ping.data(), ping.size(), t0 + std::chrono::milliseconds(100 * i)).disconnect;
  CHECK_FALSE(flooded);

  net::ClientProtocol burst(2, info);
  burst.on_frame(hello.data(), hello.size(), t0);
  int answered = 0;
  net::Outcome last;
  while (!last.disconnect && answered < 50) {
    last = burst.on_frame(ping.data(), ping.size(), t0);
    answered += !last.disconnect;
  }
  CHECK(answered == 10);  // the burst allowance, then the flood
  CHECK_THAT(last.log, Catch::StartsWith("command_flood"));
}

TEST_CASE("a WebSocket message is a frame without its length prefix, under the same caps as a TCP frame", "[net]") {
  const net::ServerInfo info;
  net::ClientProtocol client(1, info);
  const protocol::Frame oversize(net::kMaxFirstFrameBytes + 1, 0);
  CHECK(client.on_unprefixed_frame(oversize.data(), oversize.size()).disconnect);  // before Hello: 1 KiB

  net::ClientProtocol web(2, info);
  const protocol::Frame hello = protocol::encode_hello("browser", true, false);
  const net::Outcome joined =
      web.on_unprefixed_frame(hello.data() + protocol::kLengthPrefixBytes, hello.size() - protocol::kLengthPrefixBytes);
  REQUIRE(joined.command);
  CHECK(std::holds_alternative<net::JoinCommand>(joined.command->action));
  CHECK(web.max_body_bytes() == protocol::kMaxClientFrameBytes);
  const protocol::Frame garbage(64, 0xAB);
  const net::Outcome refused = web.on_unprefixed_frame(garbage.data(), garbage.size());
  CHECK(refused.disconnect);
  CHECK_THAT(refused.log, Catch::StartsWith("malformed_frame"));
}

TEST_CASE("an Error code ends the connection (protocol::ends_connection) exactly where the server disconnects after it",
          "[net]") {
  const net::ServerInfo info;
  const auto t0 = net::ClientProtocol::Clock::now();
  const protocol::Frame hello = protocol::encode_hello("viewer", false, false);
  const auto welcomed = [&] {
    auto client = std::make_unique<net::ClientProtocol>(1, info);
    client->on_frame(hello.data(), hello.size(), t0);
    client->on_reply({1, net::JoinedReply{}});
    return client;
  };
  std::vector<net::Outcome> outcomes;
  {
    net::ClientProtocol fresh(1, info);
    const protocol::Frame ping = protocol::encode_ping(1);
    outcomes.push_back(fresh.on_frame(ping.data(), ping.size(), t0));  // expected_hello
  }
  {
    net::ClientProtocol old(1, info);
    const protocol::Frame other = protocol::encode_hello("viewer", false, false, protocol::kProtocolVersion + 1);
    outcomes.push_back(old.on_frame(other.data(), other.size(), t0));  // version_mismatch
  }
  outcomes.push_back(net::ClientProtocol(1, info).on_hello_timeout());
  {
    const std::uint8_t huge[4] = {0xff, 0xff, 0xff, 0x7f};  // malformed_frame
    std::uint32_t body = 0;
    outcomes.push_back(
        welcomed()->on_broken_stream(protocol::check_length_prefix(huge, protocol::Direction::to_server, &body)));
  }
  for (bool sent : {false, true}) {
    outcomes.push_back(welcomed()->on_write_stalled(sent));
    outcomes.push_back(welcomed()->on_acks_stopped(sent));
  }
  outcomes.push_back(welcomed()->on_replies_piling_up(100));
  outcomes.push_back(welcomed()->on_evicted("the server needs the place"));
  outcomes.push_back(welcomed()->on_server_stopping("its --duration ended"));
  outcomes.push_back(welcomed()->on_queue_full());
  outcomes.push_back(welcomed()->on_player_idle());
  outcomes.push_back(
      welcomed()->on_reply({1, net::ControlRefusedReply{net::ControlRefusedReply::Why::superseded, "x"}}));

  int disconnects = 0;
  for (const net::Outcome& outcome : outcomes) {
    REQUIRE_FALSE(outcome.replies.empty());
    const protocol::Frame& last = outcome.replies.back();
    const protocol::DecodeResult decoded =
        protocol::decode_frame(last.data(), last.size(), protocol::Direction::to_client);
    REQUIRE(decoded.ok());
    REQUIRE(decoded.message->payload_type() == wire::Payload::Error);
    const wire::ErrorCode code = decoded.message->payload_as_Error()->code();
    INFO(protocol::error_code_name(code));
    CHECK(protocol::ends_connection(code) == outcome.disconnect);
    disconnects += outcome.disconnect;
  }
  CHECK(disconnects == 11);
}

TEST_CASE(
    "a player who pauses, steps or pours keeps the sphere past --player-idle, which Pings and still inputs do not",
    "[net]") {
  net::ServerInfo info;
  info.limits.player_idle_s = 120.0;
  info.limits.max_commands_per_s = 1000.0;
  net::ClientProtocol client(1, info);
  const protocol::Frame hello = protocol::encode_hello("script", true, false);
  client.on_frame(hello.data(), hello.size());
  client.on_reply({1, net::JoinedReply{3, ""}});
  REQUIRE(client.has_player());
  const auto welcomed_deadline = client.player_idle_deadline();
  REQUIRE(welcomed_deadline);
  const std::chrono::seconds idle(120);
  auto t = *welcomed_deadline - idle;  // the Welcome
  for (const protocol::Frame& use :
       {protocol::encode_pause(true), protocol::encode_step(10), protocol::encode_add_balls(5),
        protocol::encode_set_time_scale(0.5f), protocol::encode_reset("", std::nullopt)}) {
    t += std::chrono::seconds(100);  // each within the last one's 120 s: 500 s in all, the sphere kept
    client.on_frame(use.data(), use.size(), t);
    CHECK(client.player_idle_deadline() == t + idle);
  }
  const auto used = *client.player_idle_deadline();
  const protocol::Frame ping = protocol::encode_ping(1), still = protocol::encode_player_input(1, {0.0f, 0.0f, 0.0f});
  client.on_frame(ping.data(), ping.size(), used - std::chrono::seconds(10));
  client.on_frame(still.data(), still.size(), used - std::chrono::seconds(5));
  CHECK(client.player_idle_deadline() == used);  // present, but not using the sphere
}
