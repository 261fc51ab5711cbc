#pragma once
// Hand-over of snapshots from the net thread to the render thread, and the
// clock that decides which two snapshots a frame is drawn between.
//
//   net thread:    push(s)  ──► [ newest few snapshots ] ◄── frame_at(now) : render thread
//
// Snapshot interpolation: a frame at local time `now` shows the server's
// state at  now - offset - delay, where offset maps local time to server time
// (estimated from arrival times) and delay is about 1.5 snapshot intervals, so
// that the newer snapshot of the pair has almost always arrived already.
// Motion then stays smooth whatever the ratio of frame rate to snapshot rate.

#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>

#include "viewer/net/snapshot.h"

namespace fishtank::viewer {

struct RenderPair {
  std::shared_ptr<const Snapshot> from;
  std::shared_ptr<const Snapshot> to;
  float alpha = 0.0f;  // 0: from, 1: to
};

class SnapshotBuffer {
 public:
  void clear();  // a new connection: nothing old is shown against new ids
  void push(std::shared_ptr<const Snapshot> snapshot);
  // False until the first snapshot. The pair brackets the render time; both
  // are the newest one when the render time is past it.
  bool frame_at(double now, RenderPair& out) const;

  std::shared_ptr<const Snapshot> newest() const;
  double render_delay() const;  // seconds

 private:
  static constexpr std::size_t kKept = 8;  // enough for a delay of several intervals

  mutable std::mutex mutex_;
  std::deque<std::shared_ptr<const Snapshot>> snapshots_;  // oldest first
  double offset_ = 0.0;         // local time - server time of the least delayed arrival
  double mean_interval_ = 0.0;  // of server time between snapshots, smoothed
};

}  // namespace fishtank::viewer
