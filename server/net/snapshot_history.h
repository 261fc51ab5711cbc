#pragma once
// The io thread's store of recent snapshots, and the frames of the newest one.
//
//   physics thread ─► publish(s) ─► [ newest kKeptPublished snapshots ]   the bases
//   session ─► frame(newest, base, prior) ─► cache hit? ─► the same frame for every client with that base
//                                     └ miss: code a delta against base (or a keyframe: no base,
//                                       or one no longer kept), keep it for the next client
//
// Every client that acknowledged the same snapshot gets the same bytes, so
// coding costs once per distinct base, not per client: on a quiet network all
// clients acknowledge the previous snapshot and one delta serves them all. A
// client that still keeps the base and prior of a frame already coded, at most
// kShareLag older than its own base, gets that frame too: paced clients
// acknowledge different snapshots, and a large scene's frame is costly to code. The per-client part is a lookup in a
// cache of a few entries.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <vector>

#include "protocol/received_snapshots.h"
#include "server/net/snapshot_encoder.h"

namespace fishtank::net {

struct CodedSnapshot {
  protocol::SharedFrame frame;
  bool keyframe = false;
};

// Read from the physics thread's status line; written on the io thread.
struct FrameStats {
  std::atomic<std::uint64_t> snapshots{0};  // published
  std::atomic<std::uint64_t> frames{0};     // coded: keyframes and deltas
  std::atomic<std::uint64_t> keyframes{0};
  std::atomic<std::uint64_t> coding_ns{0};
  std::atomic<std::uint64_t> frame_bytes{0};  // of every frame coded
};

class SnapshotHistory {
 public:
  // Snapshots kept to code against: a client keeps its newest protocol::kKeptBases received, which
  // span more than that many published where a slow link gets only some (AckTracker): about 2 s at 60 a second.
  static constexpr std::size_t kKeptPublished = 4 * protocol::kKeptBases;
  // Bases kept at most, whatever their size, so that a huge tank keeps fewer
  // snapshots rather than gigabytes.
  static constexpr std::size_t kMaxBytes = std::size_t{256} << 20;
  // How many snapshots older than a client's own base another's frame may be coded against and still serve
  // it: a delta from further back is larger.
  static constexpr std::uint32_t kShareLag = 6;

  void publish(SharedSnapshot snapshot);
  // The frame of `snapshot` for a client that holds `base` (empty: none) and
  // `prior`, the snapshot sent to it before base (empty: none); `keeps` says
  // which other snapshots it holds (empty: none).
  CodedSnapshot frame(const SharedSnapshot& snapshot, std::optional<std::uint32_t> base,
                      std::optional<std::uint32_t> prior = std::nullopt,
                      const std::function<bool(std::uint32_t)>& keeps = nullptr);
  const FrameStats& stats() const { return stats_; }

 private:
  const PublishedSnapshot* find(std::uint32_t tick) const;
  // A cached frame of the newest snapshot that a client with `base` that `keeps` these can decode; null: none.
  const CodedSnapshot* shareable(std::optional<std::uint32_t> base,
                                 const std::function<bool(std::uint32_t)>& keeps) const;
  CodedSnapshot code(const PublishedSnapshot& snapshot, const PublishedSnapshot* base, const PublishedSnapshot* prior);

  std::deque<SharedSnapshot> kept_;  // oldest first; the newest published is last
  std::size_t kept_bytes_ = 0;
  // Frames of the newest snapshot, by the base and prior they were coded against (empty: none).
  using References = std::pair<std::optional<std::uint32_t>, std::optional<std::uint32_t>>;
  std::vector<std::pair<References, CodedSnapshot>> cache_;
  protocol::PositionsDelta delta_;  // scratch
  FrameStats stats_;
};

}  // namespace fishtank::net
