// The server's side of delta snapshots, without sockets: the physics capture
// (SnapshotEncoder), the frames by acknowledged base (SnapshotHistory) and the
// acknowledgements (AckTracker, in ClientProtocol), read back by the clients'
// ReceivedSnapshots, as sessions and clients use them.

#include "server/net/snapshot_history.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <deque>
#include <map>

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
    const net::CodedSnapshot coded =
        acks ? history.frame(s, tracker.base(), tracker.prior(), [&](std::uint32_t t) { return tracker.keeps(t); })
             : history.frame(s, std::nullopt);
    tracker.sent(s->header.tick, {}, coded.frame->size());
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

// Snapshot `tick` of two balls, the second's z at `z`.
net::SharedSnapshot two_balls(std::uint32_t tick, std::uint16_t z) {
  auto s = std::make_shared<net::PublishedSnapshot>();
  s->header.tick = tick;
  s->ball_count = 2;
  s->quantised = {1, 2, 3, 4, 5, z};
  return s;
}

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
      // The slower clients first: the first, a newer base, then decodes their frames where it keeps their bases.
      for (int c = 2; c >= 0; --c)
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
  // Frames are shared: coded one per client, n keyframes and n + n + n / 3 deltas would be 3.3 n.
  CHECK(history.stats().frames <= 3u * static_cast<std::uint64_t>(n) + 1);
  INFO("bytes per ball per snapshot: " << clients[0].bytes_per_ball() << " as deltas, " << clients[3].bytes_per_ball()
                                       << " in full");
  CHECK(clients[3].bytes_per_ball() > 6.0);
  for (int c = 0; c < 3; ++c) CHECK(clients[c].bytes_per_ball() < clients[3].bytes_per_ball());
}

TEST_CASE("clients that acknowledged the same snapshot share one frame, and an unknown base gets a keyframe",
          "[net][delta]") {
  net::SnapshotHistory history;
  const auto snapshot_at = [](std::uint32_t tick) { return two_balls(tick, static_cast<std::uint16_t>(tick)); };
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

TEST_CASE("a client that keeps another's base and prior gets the frame coded for it, within kShareLag",
          "[net][delta]") {
  net::SnapshotHistory history;
  const auto snapshot_at = [](std::uint32_t tick) { return two_balls(tick, static_cast<std::uint16_t>(10 * tick)); };
  for (std::uint32_t t = 0; t < 20; ++t) history.publish(snapshot_at(t));
  const net::SharedSnapshot newest = snapshot_at(20);
  history.publish(newest);
  // A acknowledged 12 (11 sent before it); B, sent every snapshot, acknowledged 18 and keeps 10 .. 18.
  const auto keeps_from = [](std::uint32_t first, std::uint32_t last) {
    return [=](std::uint32_t t) { return t >= first && t <= last; };
  };
  const net::CodedSnapshot a = history.frame(newest, 12, 11, keeps_from(11, 12));
  const net::CodedSnapshot b = history.frame(newest, 18, 17, keeps_from(10, 18));
  CHECK(b.frame == a.frame);  // coded once
  CHECK(history.stats().frames == 1);
  protocol::ReceivedSnapshots received;  // B's side: it decodes A's frame from what it keeps
  std::vector<std::uint16_t> positions;
  for (std::uint32_t t = 10; t <= 18; ++t) {
    const net::CodedSnapshot full = history.frame(snapshot_at(t), std::nullopt);
    REQUIRE(received
                .positions(*protocol::decode_frame(full.frame->data(), full.frame->size(), Direction::to_client)
                                .message->payload_as_Snapshot(),
                           positions)
                .empty());
  }
  const protocol::DecodeResult r = protocol::decode_frame(b.frame->data(), b.frame->size(), Direction::to_client);
  REQUIRE(received.positions(*r.message->payload_as_Snapshot(), positions).empty());
  CHECK(positions == newest->quantised);

  // Not shared: a client that was not sent A's prior, one whose base is newer than kShareLag allows, one that
  // says nothing of what it keeps.
  static_assert(12 + net::SnapshotHistory::kShareLag < 19);
  CHECK(history.frame(newest, 18, 17, keeps_from(12, 18)).frame != a.frame);
  CHECK(history.frame(newest, 19, 18, keeps_from(10, 19)).frame != a.frame);
  CHECK(history.frame(newest, 16, 15).frame != a.frame);
}

TEST_CASE("an Ack the client cannot have meant gets an Error, then a keyframe, and the connection stays",
          "[net][delta]") {
  net::ServerInfo info;
  info.variant = "sse";
  info.simd = "sse4.1";
  info.dt = 0.001f;
  net::ClientProtocol conversation(1, info);
  const auto send = [&](const protocol::Frame& f) { return conversation.on_frame(f.data(), f.size()); };
  REQUIRE(send(protocol::encode_hello("t", false, false)).command);
  conversation.on_reply({1, net::JoinedReply{}});
  REQUIRE(conversation.welcomed());
  const auto refused = [](const net::Outcome& o) {
    if (o.replies.size() != 1 || o.disconnect) return false;
    const protocol::DecodeResult r =
        protocol::decode_frame(o.replies[0].data(), o.replies[0].size(), Direction::to_client);
    return r.ok() && r.message->payload_as_Error() &&
           r.message->payload_as_Error()->code() == wire::ErrorCode::invalid_value;
  };

  CHECK(refused(send(protocol::encode_ack(0))));                                   // nothing sent yet
  for (std::uint32_t t : {10u, 11u, 13u}) conversation.on_snapshot_sent(t, 1000);  // 12 was skipped for this client
  CHECK_FALSE(conversation.delta_base());                                          // nothing acknowledged: keyframe
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
    for (std::uint32_t t = 20; t < 20 + protocol::kKeptBases; ++t) conversation.on_snapshot_sent(t, 1000);
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
    "snapshots to a client wait while more bytes are out than its link carried in its quickest round trip plus "
    "the allowance, a second at most",
    "[net][delta]") {
  using std::chrono::milliseconds;
  const net::AckTracker::Clock::time_point t0{};
  net::AckTracker tracker;
  tracker.sent(1, t0, 10'000);
  tracker.sent(2, t0 + milliseconds(17), 10'000);
  CHECK(tracker.may_send(t0 + milliseconds(500)));  // nothing acknowledged yet: as for a client that never does
  tracker.acknowledged(1, false, t0 + milliseconds(100));
  CHECK(tracker.quickest_round_trip() == milliseconds(100));
  CHECK(tracker.delivery_rate() == Approx(100'000));  // 10 kB in 100 ms
  // It carries 15 kB in 100 + 50 ms: 2 (10 kB) may be joined by another, and then the link is queueing.
  CHECK(tracker.may_send(t0 + milliseconds(100)));
  tracker.sent(3, t0 + milliseconds(117), 10'000);
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(117)));
  tracker.acknowledged(2, false, t0 + milliseconds(200));  // came back later: the quickest stays 100 ms
  CHECK(tracker.quickest_round_trip() == milliseconds(100));
  CHECK(tracker.may_send(t0 + milliseconds(200)));

  // An Ack of a later snapshot answers the earlier ones too: TCP keeps their order.
  tracker.sent(4, t0 + milliseconds(217), 10'000);
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(300)));
  tracker.acknowledged(4, false, t0 + milliseconds(400));
  CHECK(tracker.may_send(t0 + milliseconds(400)));  // nothing out

  // A client that stops acknowledging is sent a snapshot a second.
  tracker.sent(5, t0 + milliseconds(400), 10'000);
  tracker.sent(6, t0 + milliseconds(417), 10'000);
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(1416)));
  CHECK(tracker.may_send(t0 + milliseconds(1417)));
  tracker.sent(7, t0 + milliseconds(1417), 10'000);
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(1500)));

  CHECK(tracker.oldest_unanswered() == t0 + milliseconds(400));  // what the idle watchdog counts from
  // A keyframe asked for is an answer as well.
  tracker.acknowledged(7, true, t0 + milliseconds(1500));
  CHECK(tracker.may_send(t0 + milliseconds(1500)));
  CHECK_FALSE(tracker.base());
  CHECK_FALSE(tracker.oldest_unanswered());
  // Watching off: what is out needs no answer.
  tracker.sent(8, t0 + milliseconds(1600), 10'000);
  tracker.forget_unanswered();
  CHECK_FALSE(tracker.oldest_unanswered());
  CHECK(tracker.may_send(t0 + milliseconds(1700)));

  // The quickest is of the last 10 s: a path that got slower is learnt.
  for (std::uint32_t tick = 9; tick < 21; ++tick) {
    const auto sent = t0 + std::chrono::seconds(tick);
    tracker.sent(tick, sent, 10'000);
    tracker.acknowledged(tick, false, sent + milliseconds(200));
  }
  CHECK(tracker.quickest_round_trip() == milliseconds(200));
  CHECK(tracker.delivery_rate() == Approx(50'000));
}

namespace {

struct LinkRun {
  int sent_last_second = 0;
  double slowest_round_trip_last_second = 0.0;  // seconds
};

// A client behind a link of `bytes_per_s` (0: no limit) and `latency` each way, offered a snapshot of
// `frame_bytes` (the first `first_bytes`, 0: the same) every 1/60 s for `seconds`, acknowledging each as it
// arrives, on a clock of 0.1 ms ticks; the figures are of the last second.
LinkRun run_link(double bytes_per_s, double latency, std::size_t frame_bytes, std::size_t first_bytes = 0,
                 double seconds = 10.0) {
  using Clock = net::AckTracker::Clock;
  const auto at = [](double s) { return Clock::time_point{} + std::chrono::microseconds(std::lround(s * 1e6)); };
  net::AckTracker tracker;
  tracker.expect_acks();
  std::deque<std::pair<double, std::uint32_t>> acks;  // (reaches the server at, tick)
  std::map<std::uint32_t, double> sent_at;
  double link_free = 0.0, next_offer = 0.0;
  bool offered = false;
  std::uint32_t tick = 0;
  LinkRun run;
  for (double now = 0.0; now < seconds; now += 1e-4) {
    for (; !acks.empty() && acks.front().first <= now; acks.pop_front()) {
      tracker.acknowledged(acks.front().second, false, at(now));
      if (now >= seconds - 1.0)
        run.slowest_round_trip_last_second =
            std::max(run.slowest_round_trip_last_second, now - sent_at[acks.front().second]);
    }
    if (now >= next_offer) {
      offered = true;  // the newest replaces one still held
      next_offer += 1.0 / 60.0;
    }
    if (!offered || !tracker.may_send(at(now))) continue;
    offered = false;
    const double bytes = double(tick == 0 && first_bytes ? first_bytes : frame_bytes);
    tracker.sent(++tick, at(now), std::size_t(bytes));
    sent_at[tick] = now;
    run.sent_last_second += now >= seconds - 1.0;
    link_free = std::max(link_free, now + latency) + (bytes_per_s > 0.0 ? bytes / bytes_per_s : 0.0);
    acks.emplace_back(link_free + latency, tick);
  }
  return run;
}

}  // namespace

TEST_CASE("paced by its Acks, a slow link gets what it carries without a queue, and a fast one every snapshot",
          "[net][delta]") {
  // 20 kB snapshots over 50 kB/s: 2.5 a second, each 0.4 s on the link; a queue would grow by 57 kB a second.
  const LinkRun slow = run_link(50'000, 0.005, 20'000);
  CHECK(slow.sent_last_second >= 2);
  CHECK(slow.slowest_round_trip_last_second < 2 * 0.4 + 0.1);  // one snapshot ahead at most
  // 150 kB/s, 16 kB: as 6000 settled balls.
  const LinkRun medium = run_link(150'000, 0.005, 16'000);
  CHECK(medium.sent_last_second >= 8);
  CHECK(medium.slowest_round_trip_last_second < 2 * 16.0 / 150 + 0.1);
  // Far but fast (100 ms each way): six round trips' worth out at once, and all 60 a second arrive.
  const LinkRun far = run_link(0.0, 0.1, 36'000);
  CHECK(far.sent_last_second >= 59);
  CHECK(far.slowest_round_trip_last_second < 0.21);
  // 20 ms each way: a round trip spans more than one snapshot, and still all 60 a second arrive.
  CHECK(run_link(0.0, 0.02, 36'000).sent_last_second >= 59);
  // Loopback.
  CHECK(run_link(0.0, 0.00005, 36'000).sent_last_second >= 59);
}

TEST_CASE(
    "over two minutes a slow link's round trip stays what the link carries: a queueing link drains every "
    "kProbeInterval, a fast one never",
    "[net][delta]") {
  // Without the drain each 10 s window's quickest round trip had the last one's queue in it, growing.
  const LinkRun slow = run_link(50'000, 0.005, 20'000, 0, 120.0);
  CHECK(slow.sent_last_second >= 2);
  CHECK(slow.slowest_round_trip_last_second < 2 * 0.4 + 0.1);
  const LinkRun medium = run_link(150'000, 0.005, 16'000, 0, 120.0);
  CHECK(medium.sent_last_second >= 8);
  CHECK(medium.slowest_round_trip_last_second < 2 * 16.0 / 150 + 0.1);
  // A late joiner: its first round trip is a 36 kB keyframe's, then 12 kB deltas.
  const LinkRun joiner = run_link(150'000, 0.005, 12'000, 36'000, 120.0);
  CHECK(joiner.sent_last_second >= 11);
  CHECK(joiner.slowest_round_trip_last_second < 2 * 12.0 / 150 + 0.1);
  // Far but fast: never queueing, never drained, every snapshot.
  const LinkRun far = run_link(0.0, 0.1, 36'000, 0, 120.0);
  CHECK(far.sent_last_second >= 59);
  CHECK(far.slowest_round_trip_last_second < 0.21);
}

TEST_CASE("a link found queueing is let drain kProbeInterval after a snapshot last went out alone", "[net][delta]") {
  using std::chrono::milliseconds;
  const net::AckTracker::Clock::time_point t0{};
  net::AckTracker tracker;
  tracker.expect_acks();
  tracker.sent(1, t0, 10'000);
  tracker.acknowledged(1, false, t0 + milliseconds(100));  // 100 ms, 100 kB/s
  tracker.sent(2, t0 + milliseconds(100), 10'000);         // alone: nothing out before it
  tracker.sent(3, t0 + milliseconds(117), 10'000);
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(134)));  // 20 kB out, 15 kB carried: queueing
  // Until kProbeInterval after snapshot 2, paced as before: each Ack lets the next go with one still out.
  std::uint32_t tick = 3;
  auto now = t0 + milliseconds(117);
  const auto drain = t0 + milliseconds(100) + net::kProbeInterval;
  for (; now + milliseconds(100) < drain; now += milliseconds(100)) {
    tracker.acknowledged(tick - 1, false, now + milliseconds(100));
    REQUIRE(tracker.may_send(now + milliseconds(100)));
    tracker.sent(++tick, now + milliseconds(100), 10'000);
  }
  now += milliseconds(100);
  tracker.acknowledged(tick - 1, false, now);
  // Then the same one out waits: none may be out when the next goes.
  CHECK_FALSE(tracker.may_send(now));
  tracker.acknowledged(tick, false, now + milliseconds(60));
  CHECK(tracker.may_send(now + milliseconds(60)));
  tracker.sent(++tick, now + milliseconds(60), 10'000);  // alone: its round trip has no queue in it
  tracker.acknowledged(tick, false, now + milliseconds(140));
  CHECK(tracker.quickest_round_trip() == milliseconds(80));
  tracker.sent(++tick, now + milliseconds(140), 10'000);
  CHECK(tracker.may_send(now + milliseconds(157)));  // paced as before

  // A link that never queued is never drained, however long since one went out alone.
  net::AckTracker fast;
  fast.expect_acks();
  fast.sent(1, t0, 10'000);
  fast.acknowledged(1, false, t0 + milliseconds(10));
  for (std::uint32_t fast_tick = 2; fast_tick < 1000; ++fast_tick) {
    const auto at = t0 + milliseconds(10 * fast_tick);
    REQUIRE(fast.may_send(at));
    fast.sent(fast_tick, at, 10'000);
    if (fast_tick > 2) fast.acknowledged(fast_tick - 1, false, at + milliseconds(1));  // always one out
  }
}

TEST_CASE("a client that says in its Hello it acknowledges has one snapshot out until its first Ack, a second at most",
          "[net][delta]") {
  using std::chrono::milliseconds;
  const net::AckTracker::Clock::time_point t0{};
  net::AckTracker tracker;
  tracker.expect_acks();
  CHECK(tracker.may_send(t0));  // nothing out
  tracker.sent(1, t0, 36'000);
  // Over a slow link the first keyframe takes long to arrive: the next waits for its Ack instead of queueing.
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(17)));
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(999)));
  CHECK(tracker.oldest_unanswered() == t0);  // the idle watchdog counts from the first snapshot
  tracker.acknowledged(1, false, t0 + milliseconds(300));
  CHECK(tracker.quickest_round_trip() == milliseconds(300));
  CHECK(tracker.may_send(t0 + milliseconds(300)));
  // From then on its link paces it, as any client that acknowledges: 120 kB/s carries 42 kB in 300 + 50 ms.
  CHECK(tracker.delivery_rate() == Approx(120'000));
  tracker.sent(2, t0 + milliseconds(300), 16'000);
  tracker.sent(3, t0 + milliseconds(317), 16'000);
  CHECK(tracker.may_send(t0 + milliseconds(334)));
  tracker.sent(4, t0 + milliseconds(334), 16'000);
  CHECK_FALSE(tracker.may_send(t0 + milliseconds(351)));

  // One that never answers gets a snapshot a second.
  net::AckTracker silent;
  silent.expect_acks();
  silent.sent(1, t0, 36'000);
  CHECK(silent.may_send(t0 + std::chrono::seconds(1)));
}
