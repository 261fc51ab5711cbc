#pragma once
// One client connection, whatever carries it (Asio-example style: do_*
// functions start async work, handlers capture [this, self], operation_aborted
// is a normal end). This class is the conversation and its limits; the
// transport is a subclass: TcpSession (length-prefixed frames on a socket) or
// WebSession (HTTP, then one frame per WebSocket message after the /ws upgrade).
//
//   reads (the transport): one read always pending ─► a complete frame
//             ─► ClientProtocol ─► replies / commands
//   writes: one write in flight (the transport's); behind it
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

#include <boost/asio.hpp>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
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
  virtual void session_said_hello(Session& session) = 0;
  virtual void session_welcomed(Session& session) = 0;
  virtual void session_closed(Session& session) = 0;
  virtual void bytes_sent(std::size_t bytes) = 0;
  // The port the server listens on for clients (web: the browser viewer's); 0 where it does not.
  virtual std::uint16_t listening_port(bool web) const = 0;
  // A snapshot offered to a session was replaced by a newer one before it could go out: a slow link or reader.
  virtual void snapshot_skipped() = 0;
  // The frame of snapshot for a client that holds snapshots `base` (empty: none) and `prior`.
  // `keeps`: which other snapshots the client holds, so that a frame coded for another may serve it.
  virtual CodedSnapshot snapshot_frame(const SharedSnapshot& snapshot, std::optional<std::uint32_t> base,
                                       std::optional<std::uint32_t> prior,
                                       const std::function<bool(std::uint32_t)>& keeps) = 0;
};

class Session : public std::enable_shared_from_this<Session> {
 public:
  using Clock = std::chrono::steady_clock;
  // A client that has this many replies unsent is not reading: it is dropped.
  static constexpr std::size_t kMaxQueuedReplies = 64;
  // How long a session that is ending waits for its last Error to be read.
  static constexpr auto kErrorGrace = std::chrono::seconds(2);
  // Shorter while the server stops: a peer that does not read must not hold the process.
  static constexpr auto kStopGrace = std::chrono::seconds(1);

  Session(const boost::asio::any_io_executor& executor, const boost::asio::ip::tcp::endpoint& peer, std::uint32_t id,
          const ServerInfo& info, SessionOwner& owner);
  virtual ~Session() = default;
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  void start();
  void offer_snapshot(SharedSnapshot snapshot);
  void deliver(const Reply& reply);
  // Error(server_full) saying why, then the usual end: the server needs the place.
  void evict(const std::string& why);
  // Error(server_stopping) saying why, then the usual end within kStopGrace; one without Hello closes at once.
  void say_server_stopping(const std::string& why);
  void close(const std::string& reason);

  std::uint32_t id() const { return id_; }
  bool welcomed() const { return protocol_.welcomed(); }
  bool hello_received() const { return protocol_.hello_received(); }
  const boost::asio::ip::address& address() const { return address_; }

 protected:
  // For the transports, from their read handlers.
  void received_bytes() { last_received_ = Clock::now(); }
  void frame_received(const std::uint8_t* frame, std::size_t size);   // length prefix included
  void message_received(const std::uint8_t* body, std::size_t size);  // a WebSocket message: no prefix
  void stream_broken(const protocol::DecodeResult& refused);
  // After a frame: the next read, the drain of an ending session, or nothing once closed.
  void read_on();
  // The write started by write_frames() is done.
  void frames_written(const boost::system::error_code& ec, std::size_t bytes);
  // A failed read or write: the peer left, or the connection broke.
  void on_error(const boost::system::error_code& ec, const char* on_eof);
  // Sends what waits, e.g. once the transport carries frames.
  void do_write();
  bool ending() const { return close_after_write_; }
  bool server_stopping() const { return server_stopping_; }
  // A peer speaking another protocol on this port: these bytes, in its protocol, then the usual end.
  void answer_in_kind_and_close(std::vector<std::uint8_t> bytes, const std::string& log);
  SessionOwner& owner() const { return owner_; }
  bool closed() const { return closed_; }
  // A TCP frame's length prefix, checked against the cap that applies now.
  protocol::DecodeResult check_length_prefix(const std::uint8_t* prefix, std::uint32_t* body_bytes) const {
    return protocol_.check_length_prefix(prefix, body_bytes);
  }
  // The largest WebSocket message that may come next.
  std::uint32_t max_body_bytes() const { return protocol_.max_body_bytes(); }
  const std::string& peer() const { return peer_; }

 private:
  // ---- the transport ----
  // Starts reading; for a web connection, HTTP requests until the upgrade.
  virtual void start_transport() = 0;
  // Reads the next frame, then frame_received() / message_received() and read_on().
  virtual void do_read() = 0;
  // Reads and drops what the peer still sends, until it closes.
  virtual void do_drain() = 0;
  // False while the connection cannot carry frames (a web connection before the upgrade).
  virtual bool carries_frames() const = 0;
  // Sends these complete frames (length prefix included), then frames_written().
  virtual void write_frames(std::vector<boost::asio::const_buffer> frames) = 0;
  // Every reply of an ending session is out: say so to the peer (TCP: FIN; WebSocket: a close frame).
  virtual void send_farewell() = 0;
  virtual void close_transport() = 0;
  // How the connection came, for the log: "" for TCP.
  virtual const char* transport_label() const = 0;

  void carry_out(Outcome outcome);
  void arm_watchdog();
  Clock::time_point next_check(Clock::time_point now) const;
  void check_limits();

  std::uint32_t id_;
  SessionOwner& owner_;
  ClientProtocol protocol_;
  const ClientLimits& limits_;
  boost::asio::ip::address address_;
  std::string peer_;

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
  bool server_stopping_ = false;
  bool closed_ = false;
};

}  // namespace fishtank::net
