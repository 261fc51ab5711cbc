#pragma once
// One client connection (Asio-example style: do_* functions start async work,
// handlers capture [this, self], operation_aborted is a normal end).
//
//   reads:  [4-byte length] ─check cap─► [body] ─► ClientProtocol ─► replies / commands
//   writes: one async_write in flight; behind it
//             replies          a short queue (bounded: a client that does not read is dropped)
//             newest snapshot  one slot, overwritten by each new snapshot
//   so a slow reader skips snapshots and never grows the server's memory or
//   slows anyone else. The snapshot is coded when its write starts, against
//   the newest one the client acknowledged by then (a keyframe if none).
//   Everything here runs on the io thread.

#include <array>
#include <boost/asio.hpp>
#include <cstdint>
#include <deque>
#include <memory>
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
  // A client that has this many replies unsent is not reading: it is dropped.
  static constexpr std::size_t kMaxQueuedReplies = 64;

  Session(boost::asio::ip::tcp::socket socket, std::uint32_t id, const ServerInfo& info, SessionOwner& owner);

  void start();
  void offer_snapshot(SharedSnapshot snapshot);
  void deliver(const Reply& reply);
  void close(const std::string& reason);

  std::uint32_t id() const { return id_; }
  bool welcomed() const { return protocol_.welcomed(); }

 private:
  void do_read_header();
  void do_read_body(std::uint32_t body_bytes);
  void carry_out(Outcome outcome);
  void do_write();
  // A failed read or write: the peer left, or the socket broke.
  void on_error(const boost::system::error_code& ec, const char* on_eof);

  boost::asio::ip::tcp::socket socket_;
  std::uint32_t id_;
  SessionOwner& owner_;
  ClientProtocol protocol_;
  std::string peer_;

  std::array<std::uint8_t, protocol::kLengthPrefixBytes> header_{};
  protocol::Frame incoming_;

  std::deque<protocol::Frame> replies_;
  SharedSnapshot newest_snapshot_;  // waiting to be sent; replaced, never queued
  std::uint32_t kinds_sent_ = 0;    // balls whose kinds this client has been sent

  // Kept alive while the write is in flight.
  std::vector<protocol::Frame> writing_replies_;
  protocol::Frame writing_kinds_;
  protocol::SharedFrame writing_snapshot_;
  bool write_in_flight_ = false;

  bool close_after_write_ = false;
  bool closed_ = false;
};

}  // namespace fishtank::net
