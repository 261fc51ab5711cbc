#pragma once
// Which snapshot the next one sent to a client may be coded against: the
// newest one the client acknowledged (Ack) among those it was sent. Nothing
// acknowledged, an Ack with want_keyframe, or an Ack that cannot be true (a
// snapshot not sent yet, or one skipped for this client) all mean: send a
// keyframe. I/O free, owned by ClientProtocol.
//
// It also says when the next snapshot should wait. Over a link slower than the
// snapshots, every one sent joins a queue in the sockets' buffers: the picture
// falls seconds behind, its base leaves the kept ones and keyframes make it
// worse. A client that acknowledges shows how long its snapshots take to come
// back; while the oldest not yet acknowledged is out longer than the quickest
// round trip of the last kRoundTripWindow plus kQueueAllowance, the link is
// queueing and the newest snapshot waits for the next Ack instead, though never
// longer than kLongestHold (a client that acknowledged only some snapshots
// would otherwise wait for ever). A client that never acknowledges takes every
// snapshot in full as its connection allows.

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>

namespace fishtank::net {

// How much longer than its quickest round trip a client's snapshots may take before they wait.
inline constexpr std::chrono::milliseconds kQueueAllowance{50};
// ... and the longest a snapshot waits since the last went out.
inline constexpr std::chrono::seconds kLongestHold{1};
// The quickest round trip is of this span: a path that got slower (a phone roaming) is learnt within it.
inline constexpr std::chrono::seconds kRoundTripWindow{10};
// Snapshots out and not yet acknowledged whose times are kept: 4 s at 60 a second.
inline constexpr std::size_t kMaxOut = 256;

class AckTracker {
 public:
  using Clock = std::chrono::steady_clock;

  // A Snapshot with this tick went out to the client at `now` (ticks rise).
  void sent(std::uint32_t tick, Clock::time_point now);
  // Returns why the Ack cannot be true, empty when it is taken (or merely old).
  std::string acknowledged(std::uint32_t tick, bool want_keyframe, Clock::time_point now);
  // Empty: the next snapshot must be a keyframe (the client keeps only its newest kKeptBases too).
  std::optional<std::uint32_t> base() const;
  // The snapshot sent before base(), which the client holds too; empty when none is known.
  std::optional<std::uint32_t> prior() const;
  // False while the link is queueing: the next snapshot waits for an Ack.
  bool may_send(Clock::time_point now) const;
  // When the oldest snapshot not yet answered went out, for a client that acknowledges; empty when none is out.
  std::optional<Clock::time_point> oldest_unanswered() const;
  // The client asked for no more snapshots (Watching off): those out need no answer.
  void forget_unanswered() { out_.clear(); }
  // The quickest round trip of a snapshot and its Ack over kRoundTripWindow up to the newest; empty before the first.
  std::optional<Clock::duration> quickest_round_trip() const;

 private:
  struct Out {
    std::uint32_t tick;
    Clock::time_point at;
  };
  struct RoundTrip {
    Clock::time_point at;  // when the Ack came
    Clock::duration took;
  };

  std::deque<std::uint32_t> sent_;  // the newest kKeptBases ticks sent, oldest first
  std::optional<std::uint32_t> base_;
  std::deque<Out> out_;  // sent and not acknowledged (any Ack of a later one counts: TCP keeps order), oldest first
  std::deque<RoundTrip> round_trips_;  // of the window: each quicker than every later one, so the first is quickest
};

}  // namespace fishtank::net
