#pragma once
// Turns the world into a Snapshot frame, once per snapshot, on the physics
// thread. The result is immutable and shared by every session (shared_ptr), so
// the cost of a snapshot does not grow with the number of viewers.
//
// Static per-ball data (the kind) is not in the shared frame: it is kept here
// as an append-only table by ball id (ids are dense and never reused, kinds
// never change, until a scene starts again and a new table begins), shared with the sessions, and each session sends a
// client the kinds it has not had yet in a small BallKinds frame of its own (server/net/session.cpp). Why per session
// and not in the Snapshot: a slow client skips snapshots, so "balls new since the previous snapshot" differs per
// client; putting it in the shared frame would force one encode per client, and re-sending all kinds every snapshot
// would add 1 byte per ball (17 % more) for data that never changes.

#include <cstdint>
#include <memory>
#include <vector>

#include "protocol/frame_codec.h"
#include "server/physics/world.h"

namespace fishtank::net {

struct PublishedSnapshot {
  protocol::SharedFrame frame;  // the Snapshot frame, identical for every client
  // kinds_by_id->at(id) is ball id's kind, for ids < ball_count (at least).
  std::shared_ptr<const std::vector<std::uint8_t>> kinds_by_id;
  std::uint32_t ball_count = 0;
  std::uint32_t scene_start = 0;  // ball ids restart at each scene start: kinds are sent again from 0
};
using SharedSnapshot = std::shared_ptr<const PublishedSnapshot>;

class SnapshotEncoder {
 public:
  SharedSnapshot encode(const World& world, const protocol::SnapshotHeader& header);

 private:
  void extend_kinds(const World& world, std::uint32_t scene_start);

  std::vector<std::uint16_t> quantised_;  // scratch: 3 per ball, in id order
  std::vector<std::uint32_t> player_ids_;
  std::vector<Vec3> player_positions_;
  std::shared_ptr<const std::vector<std::uint8_t>> kinds_by_id_ = std::make_shared<std::vector<std::uint8_t>>();
  std::uint32_t scene_start_ = 0;  // of the kinds table
};

}  // namespace fishtank::net
