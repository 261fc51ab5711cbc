#pragma once
// A client's side of delta snapshots (protocol/snapshot_delta.h): it rebuilds
// each Snapshot's positions, full or delta, and keeps the newest few as the
// bases the server may code against (it codes against the newest one this
// client acknowledged, and the one it sent before that, never older than the
// kKeptBases snapshots it sent this client last).
// Used by fishtank-viewer and fishtank-client alike.
//
//   Snapshot ─► positions(s, out) ─ok─► Ack(s.tick)            base kept
//                                 └ error (base unknown, corrupt) ─► Ack(want_keyframe)

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "protocol/fishtank_generated.h"

namespace fishtank::protocol {

// Snapshots sent to a client that the server may code against, at most, and so every client keeps.
inline constexpr std::size_t kKeptBases = 32;

class ReceivedSnapshots {
 public:
  // Fills out with 3 * s.ball_count() values and keeps them as a base; or
  // returns why it cannot (then out is unspecified and nothing is kept).
  // s must have passed decode_frame.
  std::string positions(const wire::Snapshot& s, std::vector<std::uint16_t>& out);
  // A new connection: no base survives it.
  void clear() { kept_.clear(); }

 private:
  struct Kept {
    std::uint32_t tick;
    std::vector<std::uint16_t> positions;
  };
  const Kept* find(std::uint32_t tick) const;
  std::deque<Kept> kept_;  // oldest first
};

}  // namespace fishtank::protocol
