#pragma once
// Captures the world for a snapshot, once per snapshot, on the physics thread:
// positions quantised in ball-id order, players, the header. This is the part
// of encoding that every client shares; the frames themselves (a keyframe, or
// a delta against the snapshot a client acknowledged) are coded on the io
// thread, once per distinct base (server/net/snapshot_history.h).
//
// Static per-ball data (the kind) is not in the snapshot: it is kept here
// as an append-only table by ball id (ids are dense and never reused, kinds
// never change, until a scene starts again and a new table begins), shared
// with the sessions, and each session sends a client the kinds it has not had
// yet in a small BallKinds frame of its own (server/net/session.cpp). Why per
// session and not in the Snapshot: a slow client skips snapshots, so "balls new
// since the previous snapshot" differs per client, and re-sending all kinds
// every snapshot would add 1 byte per ball for data that never changes.

#include <cstdint>
#include <memory>
#include <vector>

#include "protocol/frame_codec.h"
#include "server/physics/world.h"

namespace fishtank::net {

// Immutable once published; shared by the io thread's history and every session.
struct PublishedSnapshot {
  protocol::SnapshotHeader header;
  std::uint32_t ball_count = 0;
  std::vector<std::uint16_t> quantised;  // 3 per ball, in id order (protocol/quantize.h)
  std::vector<std::uint32_t> player_ids;
  std::vector<Vec3> player_positions;
  // kinds_by_id->at(id) is ball id's kind, for ids < ball_count (at least).
  std::shared_ptr<const std::vector<std::uint8_t>> kinds_by_id;
  std::uint32_t scene_start = 0;  // ball ids restart at each scene start: kinds are sent again from 0
};
using SharedSnapshot = std::shared_ptr<const PublishedSnapshot>;

class SnapshotEncoder {
 public:
  SharedSnapshot encode(const World& world, const protocol::SnapshotHeader& header);

 private:
  void extend_kinds(const World& world, std::uint32_t scene_start);

  std::shared_ptr<const std::vector<std::uint8_t>> kinds_by_id_ = std::make_shared<std::vector<std::uint8_t>>();
  std::uint32_t scene_start_ = 0;  // of the kinds table
};

}  // namespace fishtank::net
