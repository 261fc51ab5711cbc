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
// worse. A client that acknowledges shows what its link carries, as TCP's BBR
// reads it: the quickest round trip of the last kRoundTripWindow, and the
// fastest rate at which its Acks answered bytes over that window. While the
// oldest snapshot out has been out kQueueAllowance longer than the quickest
// round trip, or more bytes are out than that rate delivers in that round trip
// plus kQueueAllowance, the link is queueing and the newest snapshot waits for
// the next Ack instead, though never longer than kLongestHold (a client that
// acknowledged only some snapshots would otherwise wait for ever). On a fast
// link the measured rate grows with what is sent, so nothing waits. A round
// trip measured through a queue is longer by it, and once the quicker ones have
// left the window it would let that queue stay, and grow window by window; so,
// as BBR's ProbeRTT does, a link found queueing is let drain every
// kProbeInterval: the next snapshot waits until none is out, and its round trip
// has no queue in it. A client
// that said in its Hello that it acknowledges is held from its first snapshot:
// one out until its Ack, so a slow link starts without a queue. A client that
// never acknowledges takes every snapshot in full as its connection allows.

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <utility>

namespace fishtank::net {

// How much longer than its quickest round trip a client's snapshots may take before they wait.
inline constexpr std::chrono::milliseconds kQueueAllowance{50};
// The shortest span a delivery rate is measured over, and a round trip counted at least in what may be out:
// a receiver may take in a burst faster than its link carries it.
inline constexpr std::chrono::milliseconds kRateInterval{100};
// The longest a snapshot waits since the last went out.
inline constexpr std::chrono::seconds kLongestHold{1};
// The quickest round trip is of this span: a path that got slower (a phone roaming) is learnt within it.
inline constexpr std::chrono::seconds kRoundTripWindow{10};
// How often a link found queueing is let drain, so that the quickest round trip has no queue in it.
inline constexpr std::chrono::seconds kProbeInterval{5};
// Snapshots out and not yet acknowledged whose times are kept: 4 s at 60 a second.
inline constexpr std::size_t kMaxOut = 256;

class AckTracker {
 public:
  using Clock = std::chrono::steady_clock;

  // The client said in its Hello that it answers every snapshot with an Ack.
  void expect_acks() { expects_acks_ = true; }
  // A Snapshot with this tick and size went out to the client at `now` (ticks rise).
  void sent(std::uint32_t tick, Clock::time_point now, std::size_t bytes);
  // Returns why the Ack cannot be true, empty when it is taken (or merely old).
  std::string acknowledged(std::uint32_t tick, bool want_keyframe, Clock::time_point now);
  // Empty: the next snapshot must be a keyframe (the client keeps only its newest kKeptBases too).
  std::optional<std::uint32_t> base() const;
  // The snapshot sent before base(), which the client holds too; empty when none is known.
  std::optional<std::uint32_t> prior() const;
  // Whether the client holds snapshot `tick`: sent to it among the last kKeptBases, and not after base().
  bool keeps(std::uint32_t tick) const;
  // False while the link is queueing, or draining for a round trip without a queue: the next snapshot
  // waits for an Ack. Not const: it notes that the link queued.
  bool may_send(Clock::time_point now);
  // When the oldest snapshot not yet answered went out, for a client that acknowledges; empty when none is out.
  std::optional<Clock::time_point> oldest_unanswered() const;
  // The client asked for no more snapshots (Watching off): those out need no answer.
  void forget_unanswered() { out_.clear(); }
  // The quickest round trip of a snapshot and its Ack over kRoundTripWindow up to the newest; empty before the first.
  std::optional<Clock::duration> quickest_round_trip() const;
  // The fastest the client's Acks answered bytes over kRoundTripWindow, bytes a second; 0 before the first.
  double delivery_rate() const { return rates_.best().value_or(0.0); }
  // The client answers snapshots: it said so, or an Ack showed it.
  bool acknowledges() const { return expects_acks_ || round_trips_.best(); }

 private:
  struct Out {
    std::uint32_t tick;
    Clock::time_point at;
    std::size_t bytes;
    // Bytes answered up to its sending, and when the last of them was: its Ack's rate is measured from there.
    std::uint64_t delivered;
    Clock::time_point delivered_at;
  };
  // The best of the values added over the last kRoundTripWindow (Better: std::less, the least).
  template <class T, class Better>
  class WindowBest {
   public:
    void add(Clock::time_point now, T value) {
      // Worse ones before it can never be the best again; older ones have left the window.
      while (!kept_.empty() && !Better{}(kept_.back().second, value)) kept_.pop_back();
      while (!kept_.empty() && kept_.front().first < now - kRoundTripWindow) kept_.pop_front();
      kept_.emplace_back(now, value);
    }
    std::optional<T> best() const { return kept_.empty() ? std::nullopt : std::optional<T>(kept_.front().second); }

   private:
    std::deque<std::pair<Clock::time_point, T>> kept_;  // each better than every later one: the first is best
  };

  std::deque<std::uint32_t> sent_;  // the newest kKeptBases ticks sent, oldest first
  std::optional<std::uint32_t> base_;
  std::deque<Out> out_;  // sent and not acknowledged (any Ack of a later one counts: TCP keeps order), oldest first
  WindowBest<Clock::duration, std::less<>> round_trips_;  // of snapshots and their Acks, when the Ack came
  WindowBest<double, std::greater<>> rates_;              // bytes a second the Acks answered
  std::uint64_t delivered_ = 0;                           // bytes of every snapshot answered so far
  Clock::time_point delivered_at_{};                      // when the last of them was
  Clock::time_point alone_at_{};     // when a snapshot last went out with none before it unanswered
  bool queued_since_alone_ = false;  // a snapshot waited for a queueing link since then
  bool expects_acks_ = false;
};

}  // namespace fishtank::net
