// Delta snapshots on the wire: positions coded against a base come back bit for
// bit, and every way a delta can be wrong is refused with a reason, not read.

#include "protocol/snapshot_delta.h"

#include <catch2/catch.hpp>
#include <random>

#include "protocol/frame_codec.h"
#include "protocol/received_snapshots.h"

using namespace fishtank;
using protocol::DecodeStatus;
using protocol::Direction;

namespace {

// A base of `count` random balls, and a next snapshot in which each ball stays,
// jitters by a quantum or two, or jumps anywhere, plus `added` new balls.
struct Pair {
  std::vector<std::uint16_t> base, now;
};
Pair random_pair(std::uint32_t count, std::uint32_t added, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> any(0, 65535), step(-2, 2), pick(0, 9);
  Pair p;
  for (std::uint32_t v = 0; v < 3 * count; ++v) p.base.push_back(static_cast<std::uint16_t>(any(rng)));
  p.now = p.base;
  for (std::uint32_t b = 0; b < count; ++b) {
    const int what = pick(rng);
    for (int axis = 0; axis < 3; ++axis) {
      std::uint16_t& q = p.now[3 * b + axis];
      if (what >= 7) q = static_cast<std::uint16_t>(std::clamp(q + step(rng), 0, 65535));
      if (what == 9 && axis == 1) q = static_cast<std::uint16_t>(any(rng));
    }
  }
  for (std::uint32_t v = 0; v < 3 * added; ++v) p.now.push_back(static_cast<std::uint16_t>(any(rng)));
  return p;
}

// A base of `base` (and a prior, when given, one tick before) at tick `tick`.
protocol::DeltaReference reference(const std::vector<std::uint16_t>& base, std::uint32_t tick = 0,
                                   const std::vector<std::uint16_t>* prior = nullptr) {
  protocol::DeltaReference ref;
  ref.base = base.data();
  ref.base_count = static_cast<std::uint32_t>(base.size() / 3);
  ref.base_tick = tick;
  if (prior) {
    ref.prior = prior->data();
    ref.prior_count = static_cast<std::uint32_t>(prior->size() / 3);
    ref.prior_tick = tick - 1;
  }
  return ref;
}

std::vector<std::uint16_t> round_trip(const std::vector<std::uint16_t>& base, const std::vector<std::uint16_t>& now,
                                      std::string& why) {
  protocol::PositionsDelta d;
  const auto count = static_cast<std::uint32_t>(now.size() / 3);
  protocol::encode_positions_delta(reference(base), 1, now.data(), count, d);
  std::vector<std::uint16_t> out(now.size());
  why = protocol::decode_positions_delta(reference(base), 1, d.unchanged.data(), d.unchanged.size(), d.changes.data(),
                                         d.changes.size(), count, out.data());
  return out;
}

protocol::Frame delta_frame(std::uint32_t tick, std::uint32_t base_tick, const std::vector<std::uint16_t>& base,
                            const std::vector<std::uint16_t>& now) {
  protocol::PositionsDelta d;
  const auto count = static_cast<std::uint32_t>(now.size() / 3);
  protocol::encode_positions_delta(reference(base, base_tick), tick, now.data(), count, d);
  protocol::SnapshotHeader h;
  h.tick = tick;
  return protocol::encode_delta_snapshot(h, reference(base, base_tick), d, count, nullptr, nullptr, 0);
}

protocol::Frame full_frame(std::uint32_t tick, const std::vector<std::uint16_t>& q) {
  protocol::SnapshotHeader h;
  h.tick = tick;
  return protocol::encode_snapshot(h, q.data(), static_cast<std::uint32_t>(q.size() / 3), nullptr, nullptr, 0);
}

const wire::Snapshot& snapshot_of(const protocol::Frame& f) {
  const protocol::DecodeResult r = protocol::decode_frame(f.data(), f.size(), Direction::to_client);
  REQUIRE(r.ok());
  return *r.message->payload_as_Snapshot();
}

}  // namespace

TEST_CASE("a delta rebuilds every quantised value of the snapshot exactly, whatever moved", "[protocol][delta]") {
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    const Pair p = random_pair(seed * 37, seed % 3 == 0 ? seed * 5 : 0, seed);
    std::string why;
    CHECK(round_trip(p.base, p.now, why) == p.now);
    CHECK(why.empty());
  }
  SECTION("a snapshot with fewer balls than its base (a reset) keeps only its own") {
    const Pair p = random_pair(100, 0, 7);
    const std::vector<std::uint16_t> fewer(p.now.begin(), p.now.begin() + 3 * 40);
    std::string why;
    CHECK(round_trip(p.base, fewer, why) == fewer);
    CHECK(why.empty());
  }
  SECTION("far jumps among jitter, coded at order 0 in codes over 32 bits, survive mid-stream and at its end") {
    std::vector<std::uint16_t> base(3 * 1000, 30000);
    std::vector<std::uint16_t> now = base;
    for (std::size_t b = 0; b < 1000; ++b) ++now[3 * b];
    base[3 * 500 + 1] = 0;  // the longest codes, 33 bits at order 0, their last bits ones
    now[3 * 500 + 1] = 65535;
    base[3 * 999 + 2] = 65535;
    now[3 * 999 + 2] = 0;
    protocol::PositionsDelta d;
    protocol::encode_positions_delta(reference(base), 1, now.data(), 1000, d);
    REQUIRE((d.changes[0] & 7) == 0);  // the order
    std::string why;
    CHECK(round_trip(base, now, why) == now);
    CHECK(why.empty());
  }
  SECTION("the largest jumps (0 to 65535 and back) survive") {
    const std::vector<std::uint16_t> base{0, 65535, 0, 65535, 0, 65535};
    const std::vector<std::uint16_t> now{65535, 0, 65535, 0, 65535, 0};
    std::string why;
    CHECK(round_trip(base, now, why) == now);
  }
}

TEST_CASE("balls at rest cost one bit, a quantum of jitter a few more", "[protocol][delta]") {
  std::vector<std::uint16_t> base(3 * 8000, 30000);
  std::vector<std::uint16_t> now = base;
  protocol::PositionsDelta d;
  protocol::encode_positions_delta(reference(base), 1, now.data(), 8000, d);
  CHECK(d.unchanged.size() == 1000);
  CHECK(d.changes.size() == 1);                                // the order of the codes, and no code
  for (std::size_t b = 0; b < 8000; b += 4) ++now[3 * b + 1];  // a quarter of the balls up one quantum
  protocol::encode_positions_delta(reference(base), 1, now.data(), 8000, d);
  CHECK(d.changes.size() == (3 + 2000 * 5 + 7) / 8);  // the order (0), then 1 + 3 + 1 bits each
}

TEST_CASE("a ball that was moving costs only its change of velocity, and comes back exactly", "[protocol][delta]") {
  // 1000 balls falling faster each snapshot (900 quanta, then 4 more: gravity) and drifting 7 along x.
  std::vector<std::uint16_t> prior, base, now;
  for (int b = 0; b < 1000; ++b) {
    int k = 0;
    for (std::vector<std::uint16_t>* s : {&prior, &base, &now}) {
      s->insert(s->end(), {static_cast<std::uint16_t>(1000 + 30 * b + 7 * k),
                           static_cast<std::uint16_t>(60000 - 900 * k - 2 * k * k), 30000});
      ++k;
    }
  }
  protocol::PositionsDelta predicted, plain;
  protocol::encode_positions_delta(reference(base, 5, &prior), 6, now.data(), 1000, predicted);
  protocol::encode_positions_delta(reference(base, 5), 6, now.data(), 1000, plain);
  CHECK(predicted.changes.size() * 2 < plain.changes.size());
  std::vector<std::uint16_t> out(now.size());
  CHECK(protocol::decode_positions_delta(reference(base, 5, &prior), 6, predicted.unchanged.data(),
                                         predicted.unchanged.size(), predicted.changes.data(), predicted.changes.size(),
                                         1000, out.data())
            .empty());
  CHECK(out == now);
}

TEST_CASE("a client rebuilds deltas from the bases it kept and refuses those it cannot", "[protocol][delta]") {
  const Pair p = random_pair(300, 10, 3);
  protocol::ReceivedSnapshots client;
  std::vector<std::uint16_t> out;
  const protocol::Frame key = full_frame(10, p.base);
  REQUIRE(client.positions(snapshot_of(key), out).empty());
  CHECK(out == p.base);

  SECTION("a delta against a kept base") {
    const protocol::Frame f = delta_frame(11, 10, p.base, p.now);
    CHECK(client.positions(snapshot_of(f), out).empty());
    CHECK(out == p.now);
  }
  SECTION("a prediction from a prior the client does not hold") {
    const std::vector<std::uint16_t> prior = p.base;
    protocol::PositionsDelta d;
    protocol::encode_positions_delta(reference(p.base, 10, &prior), 11, p.now.data(), 310, d);
    protocol::SnapshotHeader h;
    h.tick = 11;
    const protocol::Frame f =
        protocol::encode_delta_snapshot(h, reference(p.base, 10, &prior), d, 310, nullptr, nullptr, 0);
    CHECK_THAT(client.positions(snapshot_of(f), out), Catch::Contains("and 9, which this client does not hold"));
  }
  SECTION("an unknown base") {
    const protocol::Frame f = delta_frame(11, 9, p.base, p.now);
    CHECK_THAT(client.positions(snapshot_of(f), out), Catch::Contains("does not hold"));
  }
  SECTION("a base older than any kept") {
    for (std::uint32_t t = 11; t < 11 + protocol::kKeptBases; ++t)
      REQUIRE(client.positions(snapshot_of(full_frame(t, p.base)), out).empty());
    const protocol::Frame f = delta_frame(100, 10, p.base, p.now);
    CHECK_THAT(client.positions(snapshot_of(f), out), Catch::Contains("does not hold"));
  }
  SECTION("a base whose ball count disagrees") {
    const std::vector<std::uint16_t> other(p.base.begin(), p.base.begin() + 3 * 299);
    const protocol::Frame f = delta_frame(11, 10, other, p.now);
    CHECK_THAT(client.positions(snapshot_of(f), out), Catch::Contains("balls"));
  }
  SECTION("a changes stream cut short, or with bytes after its last ball") {
    protocol::PositionsDelta d;
    protocol::encode_positions_delta(reference(p.base, 10), 11, p.now.data(), 310, d);
    protocol::SnapshotHeader h;
    h.tick = 11;
    protocol::PositionsDelta cut = d;
    cut.changes.resize(d.changes.size() - 1);
    const protocol::Frame short_frame =
        protocol::encode_delta_snapshot(h, reference(p.base, 10), cut, 310, nullptr, nullptr, 0);
    CHECK_THAT(client.positions(snapshot_of(short_frame), out), Catch::Contains("ends inside"));
    protocol::PositionsDelta longer = d;
    longer.changes.push_back(0);
    const protocol::Frame long_frame =
        protocol::encode_delta_snapshot(h, reference(p.base, 10), longer, 310, nullptr, nullptr, 0);
    CHECK_THAT(client.positions(snapshot_of(long_frame), out), Catch::Contains("bytes after"));
  }
  SECTION("a difference that leaves the quantisation range") {
    const std::vector<std::uint16_t> low(3 * 300, 0);
    protocol::PositionsDelta d;
    std::vector<std::uint16_t> high(3 * 300, 0);
    high[0] = 5;
    protocol::encode_positions_delta(reference(high), 1, low.data(), 300, d);  // ball 0: x - 5
    protocol::SnapshotHeader h;
    h.tick = 13;
    // Sent against a base (p.base re-kept as all zeros) where x - 5 is below 0.
    REQUIRE(client.positions(snapshot_of(full_frame(12, low)), out).empty());
    const protocol::Frame f = protocol::encode_delta_snapshot(h, reference(low, 12), d, 300, nullptr, nullptr, 0);
    CHECK_THAT(client.positions(snapshot_of(f), out), Catch::Contains("outside the quantisation range"));
  }
}

TEST_CASE("delta snapshots whose shape is wrong are invalid before anyone reads them", "[protocol][delta]") {
  const Pair p = random_pair(100, 0, 5);
  protocol::PositionsDelta d;
  protocol::encode_positions_delta(reference(p.base), 1, p.now.data(), 100, d);
  protocol::SnapshotHeader h;
  const auto decode = [](const protocol::Frame& f) {
    return protocol::decode_frame(f.data(), f.size(), Direction::to_client);
  };

  SECTION("a truncated unchanged mask") {
    protocol::PositionsDelta cut = d;
    cut.unchanged.pop_back();
    const auto r = decode(protocol::encode_delta_snapshot(h, reference(p.base), cut, 100, nullptr, nullptr, 0));
    CHECK(r.status == DecodeStatus::invalid_value);
    CHECK_THAT(r.why, Catch::Contains("unchanged mask"));
  }
  SECTION("more new balls than its changes could hold (a huge ball count; found by fuzzing)") {
    CHECK(
        decode(protocol::encode_delta_snapshot(h, reference(p.base), d, 4'000'000'000u, nullptr, nullptr, 0)).status ==
        DecodeStatus::invalid_value);
  }
  SECTION("a mask for a base of another size") {
    protocol::DeltaReference other = reference(p.base);
    other.base_count = 200;
    CHECK(decode(protocol::encode_delta_snapshot(h, other, d, 300, nullptr, nullptr, 0)).status ==
          DecodeStatus::invalid_value);
  }
  SECTION("both positions and a mask") {
    flatbuffers::FlatBufferBuilder b;
    const auto positions = b.CreateVector(p.now);
    const auto mask = b.CreateVector(d.unchanged);
    const auto changes = b.CreateVector(d.changes);
    const auto ids = b.CreateVector(std::vector<std::uint32_t>{});
    const auto players = b.CreateVectorOfStructs(std::vector<wire::Vec3f>{});
    const auto s = wire::CreateSnapshot(b, 1, 0.0, 0, 0.0f, 0.0f, 100, positions, ids, players, 0, 0.0f, false, 0.0f, 0,
                                        0, nullptr, nullptr, 0.0f, 0, 0, 100, mask, changes);
    b.FinishSizePrefixed(wire::CreateMessage(b, wire::Payload::Snapshot, s.Union()), "FTNK");
    const protocol::Frame f(b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize());
    CHECK(decode(f).status == DecodeStatus::invalid_value);
  }
  SECTION("a mask without its changes") {
    flatbuffers::FlatBufferBuilder b;
    const auto mask = b.CreateVector(d.unchanged);
    const auto ids = b.CreateVector(std::vector<std::uint32_t>{});
    const auto players = b.CreateVectorOfStructs(std::vector<wire::Vec3f>{});
    const auto s = wire::CreateSnapshot(b, 1, 0.0, 0, 0.0f, 0.0f, 100, 0, ids, players, 0, 0.0f, false, 0.0f, 0, 0,
                                        nullptr, nullptr, 0.0f, 0, 0, 100, mask);
    b.FinishSizePrefixed(wire::CreateMessage(b, wire::Payload::Snapshot, s.Union()), "FTNK");
    const protocol::Frame f(b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize());
    CHECK(decode(f).status == DecodeStatus::invalid_value);
  }
  SECTION("an Ack goes to the server only") {
    const protocol::Frame ack = protocol::encode_ack(7, true);
    const auto r = protocol::decode_frame(ack.data(), ack.size(), Direction::to_server);
    REQUIRE(r.ok());
    CHECK(r.message->payload_as_Ack()->tick() == 7);
    CHECK(r.message->payload_as_Ack()->want_keyframe());
    CHECK(protocol::decode_frame(ack.data(), ack.size(), Direction::to_client).status == DecodeStatus::wrong_direction);
  }
}
