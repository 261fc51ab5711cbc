#pragma once
// The server's side of one conversation, without any I/O: what a received
// frame or a physics reply means, and what to answer. Session (session.h)
// feeds it bytes and carries out the outcome; the fuzzer feeds it directly.
//
//   awaiting_hello ──Hello(version ok)──► joining ──JoinedReply──► active
//        │  anything else, bad version, broken stream: Error, then disconnect
//
// It also enforces the per-client limits that need no clock of its own
// (client_limits.h): the first frame's size, the command rate, who may add
// balls and how many, and when a player sphere neither moved nor used is freed.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "protocol/frame_codec.h"
#include "server/control_policy.h"
#include "server/net/ack_tracker.h"
#include "server/net/client_limits.h"
#include "server/net/commands.h"
#include "server/net/rate_budget.h"

namespace fishtank::net {

// What every Welcome says about this server, and the limits every client is held to.
struct ServerInfo {
  std::string variant;  // the kernel set: "scalar", "sse" or "avx2"
  std::string simd;
  std::uint32_t worker_threads = 1;
  TankBounds tank;
  float dt = 0.0f;
  float steps_per_contact = 0.0f;  // contact duration of the lightest pair / dt
  float tolerance = 0.0f;          // the per-collision error dt was chosen for; 0: dt given
  float snapshot_rate_hz = 60.0f;
  ControlPolicy control = ControlPolicy::players;
  ClientLimits limits;
};

struct Outcome {
  std::vector<protocol::Frame> replies;  // to send, in order
  std::optional<Command> command;        // for the physics thread
  bool disconnect = false;               // after the replies are sent
  std::string log;                       // worth a line in the server log when not empty
};

// A peer's name as the log writes it (common/printable_text.h) is cut to this.
inline constexpr std::size_t kMaxNameBytes = 64;

// A Hello is a few dozen bytes: before it, a peer may announce no more than
// this, so a stranger's first length prefix cannot make the server allocate much.
inline constexpr std::uint32_t kMaxFirstFrameBytes = 1024;

class ClientProtocol {
 public:
  using Clock = std::chrono::steady_clock;

  ClientProtocol(std::uint32_t client_id, const ServerInfo& info);

  // The 4-byte length prefix of the next frame: within the direction's cap, and
  // before Hello within kMaxFirstFrameBytes. On success *body_bytes is the length.
  protocol::DecodeResult check_length_prefix(const std::uint8_t* prefix, std::uint32_t* body_bytes) const;
  // A complete frame, length prefix included (decoded and checked here).
  Outcome on_frame(const std::uint8_t* frame, std::size_t size, Clock::time_point now = Clock::now());
  // A WebSocket message: a frame without its length prefix (the bytes a TCP
  // frame has after it). It is given its prefix back and read as on_frame().
  Outcome on_unprefixed_frame(const std::uint8_t* body, std::size_t size, Clock::time_point now = Clock::now());
  // The most bytes the next frame's body may have: kMaxFirstFrameBytes before Hello.
  std::uint32_t max_body_bytes() const;
  // A length prefix that check_length_prefix() refused.
  Outcome on_broken_stream(const protocol::DecodeResult& refused);
  Outcome on_reply(const Reply& reply);
  // The command of an Outcome could not be queued (the physics is behind).
  Outcome on_queue_full();
  // The player sphere was neither moved nor used by player_idle_deadline(): it is freed
  // (Leave) and the client observes from now on.
  Outcome on_player_idle();
  // The session's clock-driven limits, each an Error and a disconnect:
  // no complete Hello in time; a write that could not finish for --idle-timeout
  // (sent_meanwhile: the peer sent bytes all the same); replies piling up unsent.
  Outcome on_hello_timeout();
  Outcome on_write_stalled(bool sent_meanwhile);
  Outcome on_replies_piling_up(std::size_t unsent);
  // A client that acknowledges answered no snapshot for --idle-timeout (sent_meanwhile: it sent other bytes).
  Outcome on_acks_stopped(bool sent_meanwhile);
  // The server needs this connection's place for a newcomer (it has not said Hello).
  Outcome on_evicted(const std::string& why);
  // The server is stopping, for this reason: the last word to every client.
  Outcome on_server_stopping(const std::string& why);

  // A Snapshot with this tick went out to the client.
  void on_snapshot_sent(std::uint32_t tick, std::size_t bytes, Clock::time_point now = Clock::now()) {
    acks_.sent(tick, now, bytes);
  }
  // False while the client's link is queueing snapshots (AckTracker): the newest waits for its next Ack.
  bool may_send_snapshot(Clock::time_point now = Clock::now()) { return acks_.may_send(now); }
  // When the oldest snapshot the client has not answered went out; empty when none is, or it never answers.
  std::optional<Clock::time_point> oldest_unanswered_snapshot() const { return acks_.oldest_unanswered(); }
  // The snapshot the next one may be coded against; empty: send a keyframe.
  std::optional<std::uint32_t> delta_base() const { return acks_.base(); }
  // The snapshot sent before that one, to predict moving balls from; empty: none.
  std::optional<std::uint32_t> delta_prior() const { return acks_.prior(); }
  // Whether the client holds snapshot `tick`, to decode a frame coded for another client against.
  bool keeps(std::uint32_t tick) const { return acks_.keeps(tick); }

  // True from the Welcome on: the client gets snapshots (while it is watching).
  bool welcomed() const { return state_ == State::active; }
  // False while the client said it wants no snapshots (Watching off: a hidden page).
  bool watching() const { return watching_; }
  bool hello_received() const { return state_ != State::awaiting_hello; }
  bool has_player() const { return has_player_; }
  const std::string& client_name() const { return name_; }
  // When the sphere will be freed unless it moves or a control comes; empty without a sphere or with
  // --player-idle 0.
  std::optional<Clock::time_point> player_idle_deadline() const;

 private:
  enum class State { awaiting_hello, joining, active };

  Outcome on_hello(const wire::Hello& hello);
  Outcome on_message(const wire::Message& message, Clock::time_point now);
  Outcome on_add_balls(std::uint32_t count, Clock::time_point now);
  Outcome refuse(wire::ErrorCode code, const std::string& why, bool disconnect);
  // --idle-timeout passed: too_slow ("the client <did> for ...") where it sent meanwhile, else idle_timeout
  // ("the client neither <neither> for ...").
  Outcome idle_refusal(bool sent_meanwhile, const std::string& did, const std::string& neither);
  // Pause, Step, Reset, SetTimeScale: allowed by the policy, values the server knows.
  Outcome on_control(const wire::Message& message);

  std::uint32_t client_id_;
  const ServerInfo& info_;
  State state_ = State::awaiting_hello;
  std::string name_;
  bool has_player_ = false;
  bool watching_ = true;
  // The last PlayerInput with a non-zero velocity, control or AddBalls, or the Welcome.
  Clock::time_point last_used_;
  RateBudget commands_;
  RateBudget ack_budget_;  // twice the snapshot rate: an Ack per snapshot, and room for a late burst
  RateBudget balls_;
  AckTracker acks_;
  protocol::Frame unprefixed_;  // on_unprefixed_frame's frame, its buffer kept for the next
};

}  // namespace fishtank::net
