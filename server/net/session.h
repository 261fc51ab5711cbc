#pragma once
// One client connection (Asio-example style: do_* functions start async work,
// handlers capture [this, self], operation_aborted is a normal end).
//
//   reads:  [4-byte length] ─check cap─► [body, its buffer growing as bytes arrive]
//             ─► ClientProtocol ─► replies / commands
//   writes: one async_write in flight; behind it
//             replies          a short queue (bounded: a client that does not read is dropped)
//             newest snapshot  one slot, overwritten by each new snapshot
//   watchdog: one timer, set to the nearest of the Hello deadline, the in-flight
//             write's stall deadline, the player sphere's idle deadline and, once
//             the session is ending, the grace its last Error gets to be read.
//   So a slow reader skips snapshots and never grows the server's memory or
//   slows anyone else. The snapshot is coded when its write starts, against
//   the newest one the client acknowledged by then (a keyframe if none).
//   Everything here runs on the io thread.
//
// Memory held for one connection: a buffer of at most kMaxFirstFrameBytes
// before Hello, then at most about twice the bytes of the frame being received
// (at most kMaxClientFrameBytes), plus at most kMaxQueuedReplies small replies.

#include <array>
#include <boost/asio.hpp>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "server/net/client_protocol.h"
#include "server/net/snapshot_history.h"

namespace fishtank::net {

class Session;

// What a session needs from the server that owns it (NetServer).
class SessionOwner {
 public:
  virtual ~SessionOwner() = default;
  virtual bool submit(Command command) = 0;  // false when the command queue is full
  virtual void session_welcomed(Session& session) = 0;
  virtual void session_closed(Session& session) = 0;
  virtual void bytes_sent(std::size_t bytes) = 0;
  // The frame of snapshot for a client that holds snapshots `base` (empty: none) and `prior`.
  virtual CodedSnapshot snapshot_frame(const SharedSnapshot& snapshot, std::optional<std::uint32_t> base,
                                       std::optional<std::uint32_t> prior) = 0;
};

class Session : public std::enable_shared_from_this<Session> {
 public:
  using Clock = std::chrono::steady_clock;
  // A client that has this many replies unsent is not reading: it is dropped.
  static constexpr std::size_t kMaxQueuedReplies = 64;
  // How long a session that is ending waits for its last Error to be read.
  static constexpr auto kErrorGrace = std::chrono::seconds(2);

  Session(boost::asio::ip::tcp::socket socket, std::uint32_t id, const ServerInfo& info, SessionOwner& owner);

  void start();
  void offer_snapshot(SharedSnapshot snapshot);
  void deliver(const Reply& reply);
  void close(const std::string& reason);

  std::uint32_t id() const { return id_; }
  bool welcomed() const { return protocol_.welcomed(); }

 private:
  void do_read_header();
  void do_read_body();
  void do_drain();
  void carry_out(Outcome outcome);
  void do_write();
  void arm_watchdog();
  Clock::time_point next_check(Clock::time_point now) const;
  void check_limits();
  // A failed read or write: the peer left, or the socket broke.
  void on_error(const boost::system::error_code& ec, const char* on_eof);

  boost::asio::ip::tcp::socket socket_;
  std::uint32_t id_;
  SessionOwner& owner_;
  ClientProtocol protocol_;
  const ClientLimits& limits_;
  std::string peer_;

  std::array<std::uint8_t, protocol::kLengthPrefixBytes> header_{};
  protocol::Frame incoming_;     // the frame being received, grown as its bytes arrive
  std::size_t frame_bytes_ = 0;  // its full size, length prefix included

  boost::asio::steady_timer watchdog_;
  Clock::time_point connected_at_ = Clock::now();
  Clock::time_point last_received_ = connected_at_;
  Clock::time_point write_started_ = connected_at_;
  std::optional<Clock::time_point> hard_close_at_;  // set once the session is ending

  std::deque<protocol::Frame> replies_;
  SharedSnapshot newest_snapshot_;  // waiting to be sent; replaced, never queued
  std::uint32_t kinds_sent_ = 0;    // balls whose kinds this client has been sent
  std::uint32_t scene_start_ = 0;   // of the last snapshot sent: kinds_sent_ counts from that start

  // Kept alive while the write is in flight.
  std::vector<protocol::Frame> writing_replies_;
  protocol::Frame writing_kinds_;
  protocol::SharedFrame writing_snapshot_;
  bool write_in_flight_ = false;

  bool close_after_write_ = false;
  bool farewell_sent_ = false;  // every reply is out and our side is shut
  bool closed_ = false;
};

}  // namespace fishtank::net
