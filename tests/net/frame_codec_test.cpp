// The frame codec: what one side encodes, the other decodes unchanged; what a
// peer can get wrong is refused with the right status before it is used.

#include "protocol/frame_codec.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <limits>

#include "protocol/fishtank_generated.h"
#include "protocol/quantize.h"

using namespace fishtank;
using protocol::DecodeStatus;
using protocol::Direction;

namespace {
protocol::DecodeResult decode(const protocol::Frame& f, Direction to) {
  return protocol::decode_frame(f.data(), f.size(), to);
}
}  // namespace

TEST_CASE("every message survives encode then decode with its values intact", "[protocol]") {
  SECTION("Hello") {
    const protocol::Frame f = protocol::encode_hello("viewer", true, true);
    const auto r = decode(f, Direction::to_server);
    REQUIRE(r.ok());
    const wire::Hello& h = *r.message->payload_as_Hello();
    CHECK(h.protocol_version() == protocol::kProtocolVersion);
    CHECK(h.client_name()->str() == "viewer");
    CHECK(h.wants_player());
    CHECK(h.acknowledges());
    const protocol::Frame silent = protocol::encode_hello("script", false, false);
    CHECK_FALSE(decode(silent, Direction::to_server).message->payload_as_Hello()->acknowledges());
  }
  SECTION("Welcome") {
    protocol::WelcomeInfo w;
    w.client_id = 7;
    w.server_variant = "sse";
    w.simd_level = "sse4.1";
    w.worker_threads = 2;
    w.dt = 0.001f;
    w.player_id = 3;
    w.snapshot_rate_hz = 60.0f;
    w.control_policy = "players may";
    w.may_control = true;
    w.steps_per_contact = 13.0f;
    w.tolerance = 0.005f;
    w.observers_may_control = true;
    const protocol::Frame f = protocol::encode_welcome(w);
    const auto r = decode(f, Direction::to_client);
    REQUIRE(r.ok());
    const wire::Welcome& m = *r.message->payload_as_Welcome();
    CHECK(m.client_id() == 7);
    CHECK(m.server_variant()->str() == "sse");
    CHECK(m.has_player());
    CHECK(m.player_id() == 3);
    REQUIRE(m.ball_kinds()->size() == kBallKinds.size());
    CHECK(m.ball_kinds()->Get(2)->diameter() == 3.0f);
    CHECK(m.tank_max()->y() == 40.0f);
    CHECK(m.control_policy()->str() == "players may");
    CHECK(m.may_control());
    CHECK(m.steps_per_contact() == 13.0f);
    CHECK(m.tolerance() == 0.005f);
    CHECK(m.observers_may_control());
  }
  SECTION("Snapshot") {
    const std::vector<std::uint16_t> q{1, 2, 3, 65535, 0, 7};
    const std::uint32_t ids[] = {4, 9};
    const Vec3 players[] = {{1, 2, 3}, {-4, 5, -6}};
    protocol::SnapshotHeader h;
    h.tick = 12;
    h.sim_time = 3.5;
    h.threads_stepping = 3;
    h.time_scale = 0.42f;
    h.paused = true;
    h.time_scale_set = 0.5f;
    h.scene = "drop";
    h.scene_start = 4;
    h.tank.min = {-50.0f, 0.0f, -30.0f};
    h.kinetic_energy_per_ball = 0.25f;
    h.contacts = 1234;
    h.max_overlap = 0.125f;
    const protocol::Frame f = protocol::encode_snapshot(h, q.data(), 2, ids, players, 2);
    const auto r = decode(f, Direction::to_client);
    REQUIRE(r.ok());
    const wire::Snapshot& s = *r.message->payload_as_Snapshot();
    CHECK(s.tick() == 12);
    CHECK(s.sim_time() == 3.5);
    CHECK(s.threads_stepping() == 3);
    CHECK(s.time_scale() == 0.42f);
    CHECK(s.paused());
    CHECK(s.time_scale_set() == 0.5f);
    CHECK(s.scene()->str() == "drop");
    CHECK(s.scene_start() == 4);
    CHECK(s.tank_min()->x() == -50.0f);
    CHECK(s.tank_max()->x() == 20.0f);
    CHECK(s.kinetic_energy_per_ball() == 0.25f);
    CHECK(s.contacts() == 1234);
    CHECK(s.max_overlap() == 0.125f);
    CHECK(std::vector<std::uint16_t>(s.positions()->begin(), s.positions()->end()) == q);
    CHECK(s.player_ids()->Get(1) == 9);
    CHECK(s.player_positions()->Get(1)->z() == -6.0f);
  }
  SECTION("Pause, Step, Reset, SetTimeScale") {
    const protocol::Frame resume = protocol::encode_pause(false);
    const auto p = decode(resume, Direction::to_server);
    REQUIRE(p.ok());
    CHECK_FALSE(p.message->payload_as_Pause()->paused());
    const protocol::Frame step = protocol::encode_step(25);
    CHECK(decode(step, Direction::to_server).message->payload_as_Step()->count() == 25);
    const protocol::Frame reset = protocol::encode_reset("wide", 9);
    const auto r = decode(reset, Direction::to_server);
    REQUIRE(r.ok());
    CHECK(r.message->payload_as_Reset()->scene()->str() == "wide");
    CHECK(r.message->payload_as_Reset()->seed().value() == 9);
    // No scene and no seed: both absent, not an empty name and seed 0.
    const protocol::Frame plain = protocol::encode_reset("", std::nullopt);
    const auto same = decode(plain, Direction::to_server);
    REQUIRE(same.ok());
    CHECK(same.message->payload_as_Reset()->scene() == nullptr);
    CHECK_FALSE(same.message->payload_as_Reset()->seed().has_value());
    const protocol::Frame scale = protocol::encode_set_time_scale(0.25f);
    CHECK(decode(scale, Direction::to_server).message->payload_as_SetTimeScale()->scale() == 0.25f);
  }
  SECTION("BallKinds, AddBalls, Ping, Pong, Error, PlayerGranted, InLine, Watching") {
    const std::uint8_t kinds[] = {0, 1, 2, 1};
    // A decoded message points into its frame, so the frames outlive the checks.
    const protocol::Frame kinds_frame = protocol::encode_ball_kinds(10, kinds, 4);
    auto k = decode(kinds_frame, Direction::to_client);
    REQUIRE(k.ok());
    CHECK(k.message->payload_as_BallKinds()->kinds()->Get(2) == 2);
    CHECK(decode(protocol::encode_add_balls(1000), Direction::to_server).ok());
    CHECK(decode(protocol::encode_ping(42), Direction::to_server).ok());
    CHECK(decode(protocol::encode_pong(42), Direction::to_client).message->payload_as_Pong()->client_time_us() == 42);
    const protocol::Frame error_frame = protocol::encode_error(wire::ErrorCode::tank_full, "full");
    auto e = decode(error_frame, Direction::to_client);
    REQUIRE(e.ok());
    CHECK(e.message->payload_as_Error()->code() == wire::ErrorCode::tank_full);
    const protocol::Frame granted_frame = protocol::encode_player_granted(7, true);
    auto g = decode(granted_frame, Direction::to_client);
    REQUIRE(g.ok());
    CHECK(g.message->payload_as_PlayerGranted()->player_id() == 7);
    CHECK(g.message->payload_as_PlayerGranted()->may_control());
    CHECK(decode(granted_frame, Direction::to_server).status == DecodeStatus::wrong_direction);
    CHECK(decode(protocol::encode_in_line(3), Direction::to_client).message->payload_as_InLine()->ahead() == 3);
    const protocol::Frame watching_frame = protocol::encode_watching(false);
    auto w = decode(watching_frame, Direction::to_server);
    REQUIRE(w.ok());
    CHECK_FALSE(w.message->payload_as_Watching()->on());
    CHECK(decode(watching_frame, Direction::to_client).status == DecodeStatus::wrong_direction);
  }
}

TEST_CASE("positions quantised to 16 bits come back within half a step", "[protocol]") {
  const TankBounds tank;
  const float max_error = protocol::quantization_error(tank.min.x, tank.max.x);
  CHECK(max_error < 0.00031f);
  for (float x : {-20.0f, -19.99f, -0.0001f, 0.0f, 3.14159f, 19.9999f, 20.0f}) {
    std::uint16_t q[3];
    protocol::quantize_position({x, x + 20.0f, -x}, tank, q);
    const Vec3 back = protocol::dequantize_position(q, tank);
    CHECK(std::abs(back.x - x) <= max_error * 1.01f);
    CHECK(std::abs(back.y - (x + 20.0f)) <= max_error * 1.01f);
  }
}

TEST_CASE("a length prefix outside 8 .. the direction's cap is refused before any allocation", "[protocol]") {
  std::uint32_t body = 0;
  const std::uint8_t huge[4] = {0xff, 0xff, 0xff, 0x7f};
  CHECK(protocol::check_length_prefix(huge, Direction::to_server, &body).status == DecodeStatus::bad_length);
  const std::uint8_t two_mib[4] = {0, 0, 0x20, 0};  // 2 MiB: over the client cap, under the server's
  CHECK(protocol::check_length_prefix(two_mib, Direction::to_server, &body).stream_broken());
  CHECK(protocol::check_length_prefix(two_mib, Direction::to_client, &body).ok());
  CHECK(body == 2u << 20);
  const std::uint8_t zero[4] = {0, 0, 0, 0};
  CHECK(protocol::check_length_prefix(zero, Direction::to_server, &body).stream_broken());
}

TEST_CASE("frames a peer got wrong are refused with a status that says whether the stream survives", "[protocol]") {
  SECTION("a wrong file identifier breaks the stream") {
    protocol::Frame f = protocol::encode_ping(1);
    std::memcpy(f.data() + 8, "XXXX", 4);
    CHECK(decode(f, Direction::to_server).status == DecodeStatus::malformed);
  }
  SECTION("a corrupted offset fails verification and breaks the stream") {
    protocol::Frame f = protocol::encode_hello("x", false, false);
    f[4] = 0xf0;  // root offset points past the end
    CHECK(decode(f, Direction::to_server).status == DecodeStatus::malformed);
  }
  SECTION("NaN and infinite velocities are invalid values; the stream survives") {
    const auto nan = decode(protocol::encode_player_input(1, {std::nanf(""), 0, 0}), Direction::to_server);
    CHECK(nan.status == DecodeStatus::invalid_value);
    CHECK_FALSE(nan.stream_broken());
    const float inf = std::numeric_limits<float>::infinity();
    CHECK(decode(protocol::encode_player_input(1, {0, inf, 0}), Direction::to_server).status ==
          DecodeStatus::invalid_value);
  }
  SECTION("AddBalls outside 1 .. kMaxAddBallsPerRequest is an invalid value") {
    CHECK(decode(protocol::encode_add_balls(0), Direction::to_server).status == DecodeStatus::invalid_value);
    CHECK(decode(protocol::encode_add_balls(protocol::kMaxAddBallsPerRequest + 1), Direction::to_server).status ==
          DecodeStatus::invalid_value);
  }
  SECTION("a time scale outside 0.1 .. 1 or NaN, a Step of 0 or too many, a long scene name are invalid values") {
    for (float scale : {0.05f, 1.5f, -1.0f, std::nanf("")}) {
      INFO(scale);
      const auto r = decode(protocol::encode_set_time_scale(scale), Direction::to_server);
      CHECK(r.status == DecodeStatus::invalid_value);
      CHECK(r.why.find("between 0.1 and 1") != std::string::npos);
    }
    CHECK(decode(protocol::encode_set_time_scale(0.1f), Direction::to_server).ok());
    CHECK(decode(protocol::encode_set_time_scale(1.0f), Direction::to_server).ok());
    CHECK(decode(protocol::encode_step(0), Direction::to_server).status == DecodeStatus::invalid_value);
    CHECK(decode(protocol::encode_step(protocol::kMaxStepsPerRequest + 1), Direction::to_server).status ==
          DecodeStatus::invalid_value);
    CHECK(decode(protocol::encode_reset(std::string(40, 'x'), std::nullopt), Direction::to_server).status ==
          DecodeStatus::invalid_value);
  }
  SECTION("a snapshot whose tank is inside out is an invalid value") {
    protocol::SnapshotHeader h;
    h.tank.min = {30.0f, 0.0f, -20.0f};
    const std::uint16_t q[3] = {};
    const std::uint32_t id = 0;
    const Vec3 player{};
    CHECK(decode(protocol::encode_snapshot(h, q, 1, &id, &player, 1), Direction::to_client).status ==
          DecodeStatus::invalid_value);
  }
  SECTION("a server message sent to the server is refused as the wrong direction") {
    CHECK(decode(protocol::encode_pong(1), Direction::to_server).status == DecodeStatus::wrong_direction);
    CHECK(decode(protocol::encode_ping(1), Direction::to_client).status == DecodeStatus::wrong_direction);
  }
  SECTION("a union type without its table is an invalid value, not a null dereference (found by fuzzing)") {
    flatbuffers::FlatBufferBuilder b;
    b.FinishSizePrefixed(wire::CreateMessage(b, wire::Payload::Hello, /*payload=*/0), "FTNK");
    const protocol::Frame f(b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize());
    CHECK(decode(f, Direction::to_server).status == DecodeStatus::invalid_value);
  }
  SECTION("a snapshot without its positions vector is invalid, even with no balls (found by fuzzing)") {
    flatbuffers::FlatBufferBuilder b;
    const auto snapshot = wire::CreateSnapshot(b, 0, 0.0, 0, 0.0f, 0.0f, /*ball_count=*/0);
    b.FinishSizePrefixed(wire::CreateMessage(b, wire::Payload::Snapshot, snapshot.Union()), "FTNK");
    const protocol::Frame f(b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize());
    CHECK(decode(f, Direction::to_client).status == DecodeStatus::invalid_value);
  }
  SECTION("a snapshot whose time scale is not finite is invalid") {
    protocol::SnapshotHeader h;
    h.time_scale = std::numeric_limits<float>::quiet_NaN();
    const std::uint16_t q[3] = {1, 2, 3};
    const protocol::Frame f = protocol::encode_snapshot(h, q, 1, nullptr, nullptr, 0);
    CHECK(decode(f, Direction::to_client).status == DecodeStatus::invalid_value);
  }
  SECTION("a snapshot whose position count disagrees with its ball count is invalid") {
    flatbuffers::FlatBufferBuilder b;
    const std::uint16_t q[6] = {};
    const auto positions = b.CreateVector(q, 6);
    const auto ids = b.CreateVector(std::vector<std::uint32_t>{});
    const auto players = b.CreateVectorOfStructs(std::vector<wire::Vec3f>{});
    const auto snapshot = wire::CreateSnapshot(b, 0, 0.0, 0, 0.0f, 0.0f, /*ball_count=*/3, positions, ids, players);
    b.FinishSizePrefixed(wire::CreateMessage(b, wire::Payload::Snapshot, snapshot.Union()), "FTNK");
    const protocol::Frame f(b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize());
    CHECK(decode(f, Direction::to_client).status == DecodeStatus::invalid_value);
  }
}

TEST_CASE("snapshots of any ball and player count verify (regression: 12-byte struct vectors)", "[protocol]") {
  for (std::uint32_t balls : {0u, 1u, 2u, 3u, 530u}) {
    for (std::size_t players : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{8}}) {
      const std::vector<std::uint16_t> q(3 * balls, 5);
      const std::vector<std::uint32_t> ids(players, 1);
      const std::vector<Vec3> positions(players, Vec3{1, 2, 3});
      const protocol::Frame f = protocol::encode_snapshot({}, q.data(), balls, ids.data(), positions.data(), players);
      INFO(balls << " balls, " << players << " players");
      CHECK(decode(f, Direction::to_client).ok());
    }
  }
}

TEST_CASE("FrameReader splits a stream cut anywhere into the frames that were sent", "[protocol]") {
  protocol::Frame stream;
  for (std::uint32_t i = 0; i < 5; ++i) {
    const protocol::Frame f = protocol::encode_pong(i);
    stream.insert(stream.end(), f.begin(), f.end());
  }
  for (std::size_t chunk : {std::size_t{1}, std::size_t{3}, std::size_t{7}, stream.size()}) {
    protocol::FrameReader reader(Direction::to_client);
    std::uint32_t expected = 0;
    for (std::size_t at = 0; at < stream.size(); at += chunk) {
      reader.append(stream.data() + at, std::min(chunk, stream.size() - at));
      while (auto r = reader.next()) {
        REQUIRE(r->ok());
        CHECK(r->message->payload_as_Pong()->client_time_us() == expected++);
      }
    }
    CHECK(expected == 5);
  }
}
