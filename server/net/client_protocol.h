#pragma once
// The server's side of one conversation, without any I/O: what a received
// frame or a physics reply means, and what to answer. Session (session.h)
// feeds it bytes and carries out the outcome; the fuzzer feeds it directly.
//
//   awaiting_hello ──Hello(version ok)──► joining ──JoinedReply──► active
//        │  anything else, bad version, broken stream: Error, then disconnect

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "protocol/frame_codec.h"
#include "server/net/ack_tracker.h"
#include "server/net/commands.h"

namespace fishtank::net {

// What every Welcome says about this server.
struct ServerInfo {
  std::string variant;  // the kernel set: "scalar", "sse" or "avx2"
  std::string simd;
  std::uint32_t worker_threads = 1;
  TankBounds tank;
  float dt = 0.0f;
  float snapshot_rate_hz = 60.0f;
};

struct Outcome {
  std::vector<protocol::Frame> replies;  // to send, in order
  std::optional<Command> command;        // for the physics thread
  bool disconnect = false;               // after the replies are sent
  std::string log;                       // worth a line in the server log when not empty
};

// A peer's name as it may be written to the log: control and non-ASCII bytes
// as \xNN, so that a name cannot forge a line, cut to kMaxNameBytes.
std::string printable_name(const std::string& raw);
inline constexpr std::size_t kMaxNameBytes = 64;

class ClientProtocol {
 public:
  ClientProtocol(std::uint32_t client_id, const ServerInfo& info) : client_id_(client_id), info_(info) {}

  // A complete frame, length prefix included (decoded and checked here).
  Outcome on_frame(const std::uint8_t* frame, std::size_t size);
  // A length prefix that check_length_prefix() refused.
  Outcome on_broken_stream(const protocol::DecodeResult& refused);
  Outcome on_reply(const Reply& reply);
  // The command of an Outcome could not be queued (the physics is behind).
  Outcome on_queue_full();

  // A Snapshot with this tick went out to the client.
  void on_snapshot_sent(std::uint32_t tick) { acks_.sent(tick); }
  // The snapshot the next one may be coded against; empty: send a keyframe.
  std::optional<std::uint32_t> delta_base() const { return acks_.base(); }
  // The snapshot sent before that one, to predict moving balls from; empty: none.
  std::optional<std::uint32_t> delta_prior() const { return acks_.prior(); }

  // True from the Welcome on: the client gets snapshots.
  bool welcomed() const { return state_ == State::active; }
  const std::string& client_name() const { return name_; }

 private:
  enum class State { awaiting_hello, joining, active };

  Outcome on_hello(const wire::Hello& hello);
  Outcome on_message(const wire::Message& message);
  Outcome refuse(wire::ErrorCode code, const std::string& why, bool disconnect);

  std::uint32_t client_id_;
  const ServerInfo& info_;
  State state_ = State::awaiting_hello;
  std::string name_;
  AckTracker acks_;
};

}  // namespace fishtank::net
