// The server's side of delta snapshots, without sockets: the physics capture
// (SnapshotEncoder), the frames by acknowledged base (SnapshotHistory) and the
// acknowledgements (AckTracker, in ClientProtocol), read back by the clients'
// ReceivedSnapshots, as sessions and clients use them.

#include "server/net/snapshot_history.h"

#include <catch2/catch.hpp>
#include <deque>

#include "protocol/received_snapshots.h"
#include "server/net/ack_tracker.h"
#include "server/net/client_protocol.h"

using namespace fishtank;
using protocol::Direction;

namespace {

// One simulated client: it receives every `every`-th snapshot, and the server
// hears of each Ack `lag` snapshots after it was sent.
struct SimulatedClient {
  int every = 1;
  int lag = 0;
  bool acks = true;
  net::AckTracker tracker;
  protocol::ReceivedSnapshots received;
  std::deque<std::pair<int, std::uint32_t>> acks_in_flight;  // (arrives at snapshot, tick)
  std::uint64_t bytes = 0, ball_snapshots = 0;

  // Returns the positions it decoded, or nothing when this snapshot is skipped for it.
  std::optional<std::vector<std::uint16_t>> receive(int n, net::SnapshotHistory& history,
                                                    const net::SharedSnapshot& s) {
    while (!acks_in_flight.empty() && acks_in_flight.front().first <= n) {
      REQUIRE(tracker.acknowledged(acks_in_flight.front().second, false, {}).empty());
      acks_in_flight.pop_front();
    }
    if (n % every != 0) return std::nullopt;
    const net::CodedSnapshot coded = history.frame(s, acks ? tracker.base() : std::nullopt);
    tracker.sent(s->header.tick, {});
    const protocol::DecodeResult r =
        protocol::decode_frame(coded.frame->data(), coded.frame->size(), Direction::to_client);
    REQUIRE(r.ok());
    std::vector<std::uint16_t> positions;
    const std::string why = received.positions(*r.message->payload_as_Snapshot(), positions);
    INFO(why);
    REQUIRE(why.empty());
    if (acks) acks_in_flight.emplace_back(n + lag, s->header.tick);
    bytes += coded.frame->size();
    ball_snapshots += s->ball_count;
    return positions;
  }
  double bytes_per_ball() const { return ball_snapshots ? static_cast<double>(bytes) / ball_snapshots : 0.0; }
};

}  // namespace

TEST_CASE("over a pour, a settle and a plough, every delta decodes to the full snapshot's positions", "[net][delta]") {
  World world(PhysicsParams{}, kSseKernels, 1, 11);
  net::SnapshotEncoder encoder;
  net::SnapshotHistory history;
  const int steps_per_snapshot = static_cast<int>(std::lround(1.0 / 60.0 / world.dt()));
  // Every snapshot, acks heard 3 snapshots late, every third snapshot (a slow reader), and no acks at all.
  std::vector<SimulatedClient> clients(4);
  clients[1].lag = 3;
  clients[2].every = 3;
  clients[3].acks = false;

  int n = 0;
  std::uint64_t compared = 0;
  const auto run = [&](double seconds) {
    for (double t = 0.0; t < seconds; t += steps_per_snapshot * world.dt(), ++n) {
      for (int s = 0; s < steps_per_snapshot; ++s) world.step();
      protocol::SnapshotHeader header;
      header.tick = static_cast<std::uint32_t>(n);
      const net::SharedSnapshot snapshot = encoder.encode(world, header);
      history.publish(snapshot);
      const auto full = clients[3].receive(n, history, snapshot);
      REQUIRE(*full == snapshot->quantised);
      for (int c = 0; c < 3; ++c)
        if (const auto decoded = clients[c].receive(n, history, snapshot)) {
          REQUIRE(*decoded == *full);
          ++compared;
        }
    }
  };
  world.add_balls(1200);
  run(3.0);  // pour: the balls fall from the top, ~2.9 s to the floor
  run(2.0);  // settle
  const std::uint32_t player = world.add_player();
  world.set_player_velocity(player, {0.0f, -10.0f, 0.0f});
  run(1.5);  // plough: down into the pile...
  world.set_player_velocity(player, {10.0f, 0.0f, 0.0f});
  run(1.0);  // ...and through it

  CHECK(compared > 500);
  INFO("bytes per ball per snapshot: " << clients[0].bytes_per_ball() << " as deltas, " << clients[3].bytes_per_ball()
                                       << " in full");
  CHECK(clients[3].bytes_per_ball() > 6.0);
  for (int c = 0; c < 3; ++c) CHECK(clients[c].bytes_per_ball() < clients[3].bytes_per_ball());
}

TEST_CASE("clients that acknowledged the same snapshot share one frame, and an unknown base gets a keyframe",
          "[net][delta]") {
  net::SnapshotHistory history;
  const auto snapshot_at = [](std::uint32_t tick) {
    auto s = std::make_shared<net::PublishedSnapshot>();
    s->header.tick = tick;
    s->ball_count = 2;
    s->quantised = {1, 2, 3, 4, 5, static_cast<std::uint16_t>(tick)};
    return net::SharedSnapshot(s);
  };
  for (std::uint32_t t = 0; t < 5; ++t) history.publish(snapshot_at(t));
  const net::SharedSnapshot newest = snapshot_at(5);
  history.publish(newest);

  const net::CodedSnapshot a = history.frame(newest, 4);
  const net::CodedSnapshot b = history.frame(newest, 4);
  CHECK_FALSE(a.keyframe);
  CHECK(a.frame == b.frame);  // the same bytes, coded once
  CHECK(history.frame(newest, 3).frame != a.frame);
  CHECK(history.stats().frames == 2);
  CHECK(history.frame(newest, std::nullopt).keyframe);
  CHECK(history.frame(newest, 77).keyframe);  // never published
  CHECK(history.frame(newest, 5).keyframe);   // itself is no base

  SECTION("a base older than the history keeps is answered with a keyframe") {
    for (std::uint32_t t = 6; t < 6 + net::SnapshotHistory::kKeptPublished; ++t) history.publish(snapshot_at(t));
    const net::SharedSnapshot later = snapshot_at(1000);
    history.publish(later);
    CHECK(history.frame(later, 4).keyframe);
    CHECK_FALSE(history.frame(later, 7).keyframe);  // more than 32 ago: a base of a client that got few of them
    CHECK_FALSE(history.frame(later, 6 + net::SnapshotHistory::kKeptPublished - 1).keyframe);
  }
}

TEST_CASE("an Ack the client cannot have meant gets an Error, then a keyframe, and the connection stays",
          "[net][delta]") {
  net::ServerInfo info;
  info.variant = "sse";
  info.simd = "sse4.1";
  info.dt = 0.001f;
  net::ClientProtocol conversation(1, info);
  const auto send = [&](const protocol::Frame& f) { return conversation.on_frame(f.data(), f.size()); };
  REQUIRE(send(protocol::encode_hello("t", false)).command);
  conversation.on_reply({1, net::JoinedReply{}});
  REQUIRE(conversation.welcomed());
  const auto refused = [](const net::Outcome& o) {
    if (o.replies.size() != 1 || o.disconnect) return false;
    const protocol::DecodeResult r =
        protocol::decode_frame(o.replies[0].data(), o.replies[0].size(), Direction::to_client);
    return r.ok() && r.message->payload_as_Error() &&
           r.message->payload_as_Error()->code() == wire::ErrorCode::invalid_value;
  };

  CHECK(refused(send(protocol::encode_ack(0))));                             // nothing sent yet
  for (std::uint32_t t : {10u, 11u, 13u}) conversation.on_snapshot_sent(t);  // 12 was skipped for this client
  CHECK_FALSE(conversation.delta_base());                                    // nothing acknowledged: keyframe
  CHECK(send(protocol::encode_ack(11)).replies.empty());
  CHECK(conversation.delta_base() == 11u);
  CHECK(conversation.delta_prior() == 10u);               // the one sent before it, to predict moving balls from
  CHECK(send(protocol::encode_ack(10)).replies.empty());  // older than the base: kept at 11
  CHECK(conversation.delta_base() == 11u);

  SECTION("an ack for a future snapshot") {
    const net::Outcome o = send(protocol::encode_ack(14));
    CHECK(refused(o));
    CHECK_THAT(o.log, Catch::Contains("not been sent yet"));
    CHECK_FALSE(conversation.delta_base());
  }
  SECTION("an ack for a snapshot skipped for this client") {
    const net::Outcome o = send(protocol::encode_ack(12));
    CHECK(refused(o));
    CHECK_THAT(o.log, Catch::Contains("skipped"));
    CHECK_FALSE(conversation.delta_base());
  }
  SECTION("a keyframe asked for") {
    CHECK(send(protocol::encode_ack(13, /*want_keyframe=*/true)).replies.empty());
    CHECK_FALSE(conversation.delta_base());
  }
  SECTION("an ack older than any kept is harmless, and a base the client no longer keeps is none") {
    for (std::uint32_t t = 20; t < 20 + protocol::kKeptBases; ++t) conversation.on_snapshot_sent(t);
    CHECK(send(protocol::encode_ack(13)).replies.empty());
    CHECK_FALSE(conversation.delta_base());  // 11 left the client's kept bases with the 32 sent since
    CHECK(send(protocol::encode_ack(40)).replies.empty());
    CHECK(conversation.delta_base() == 40u);
  }
}

TEST_CASE("a delta that would be larger than the full snapshot is sent in full", "[net][delta]") {
  net::SnapshotHistory history;
  const auto snapshot_at = [](std::uint32_t tick, std::uint16_t value) {
    auto s = std::make_shared<net::PublishedSnapshot>();
    s->header.tick = tick;
    s->ball_count = 100;
    s->quantised.assign(300, value);
    return net::SharedSnapshot(s);
  };
  history.publish(snapshot_at(0, 0));
  const net::SharedSnapshot jumped = snapshot_at(1, 65535);  // every ball across the tank: 35 bits per axis
  history.publish(jumped);
  const net::CodedSnapshot coded = history.frame(jumped, 0);
  CHECK(coded.keyframe);
  const protocol::DecodeResult r =
      protocol::decode_frame(coded.frame->data(), coded.frame->size(), Direction::to_client);
  REQUIRE(r.ok());
  CHECK(r.message->payload_as_Snapshot()->positions()->size() == 300);
}

TEST_CASE(
    "snapshots to a client wait while its Acks lag its quickest round trip by more than the allowance, "
    "a second at most",
    "[net][delta]") {
  using std::chrono::milliseconds;
  const net::AckTracker::Clock::time_point t0{};
  net::AckTracker tracker;
  tracker.sent(1, t0);
  tracker.sent(2, t0 + milliseconds(17));
  CHECK(tracker.may_send(t0 + milliseconds(500)));  // nothing acknowledged yet: as for a client that never does
  tracker.acknowledged(1, false, t0 + milliseconds(10));
  CHECK(tracker.quickest_round_trip() == milliseconds(10));
  // 2 is out: it may be out for 10 + 50 ms before the link counts as queueing.
  CHECK(tracker.may_send(t0 + milliseconds(17 + 60)));
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(17 + 61)));
  tracker.acknowledged(2, false, t0 + milliseconds(200));  // came back late: the quickest stays 10 ms
  CHECK(tracker.quickest_round_trip() == milliseconds(10));
  CHECK(tracker.may_send(t0 + milliseconds(200)));  // nothing out

  // An Ack of a later snapshot answers the earlier ones too: TCP keeps their order.
  tracker.sent(3, t0 + milliseconds(200));
  tracker.sent(4, t0 + milliseconds(217));
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(300)));
  tracker.acknowledged(4, false, t0 + milliseconds(305));
  CHECK(tracker.may_send(t0 + milliseconds(305)));

  // A client that stops acknowledging is sent a snapshot a second.
  tracker.sent(5, t0 + milliseconds(305));
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(1304)));
  CHECK(tracker.may_send(t0 + milliseconds(1305)));
  tracker.sent(6, t0 + milliseconds(1305));
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(1400)));

  CHECK(tracker.oldest_unanswered() == t0 + milliseconds(305));  // what the idle watchdog counts from
  // A keyframe asked for is an answer as well.
  tracker.acknowledged(6, true, t0 + milliseconds(1400));
  CHECK(tracker.may_send(t0 + milliseconds(1400)));
  CHECK_FALSE(tracker.base());
  CHECK_FALSE(tracker.oldest_unanswered());
  // Watching off: what is out needs no answer.
  tracker.sent(7, t0 + milliseconds(1500));
  tracker.forget_unanswered();
  CHECK_FALSE(tracker.oldest_unanswered());
  CHECK(tracker.may_send(t0 + milliseconds(1600)));

  // The quickest is of the last 10 s: a path that got slower is learnt.
  for (std::uint32_t tick = 8; tick < 20; ++tick) {
    const auto sent = t0 + std::chrono::seconds(tick);
    tracker.sent(tick, sent);
    tracker.acknowledged(tick, false, sent + milliseconds(100));
  }
  CHECK(tracker.quickest_round_trip() == milliseconds(100));
}
