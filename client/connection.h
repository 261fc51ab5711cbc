#pragma once
// One client connection to a fishtank-server, on a caller-owned io_context
// (several connections can share one thread). It says Hello, keeps the newest
// snapshot's state and counts what it receives; writes are queued, one in flight.
// It acknowledges every snapshot it decodes, so the server sends deltas.
// Used by fishtank-client and by the network tests.

#include <boost/asio.hpp>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "protocol/frame_codec.h"
#include "protocol/received_snapshots.h"

namespace fishtank::client {

struct ConnectionStats {
  std::uint64_t snapshots = 0;
  std::uint64_t bytes_received = 0;
  std::uint64_t keyframes = 0;           // snapshots sent in full; the others were deltas
  std::uint64_t kinds_received = 0;      // ball kinds in every BallKinds message, summed: each ball's once
  std::vector<double> rtt_ms;            // one per Pong
  std::vector<std::string> errors;       // Error messages, "code: message"
  std::vector<std::string> error_codes;  // the code of each Error, e.g. "too_slow"
  bool player_granted = false;           // a sphere freed by another client came to this one (PlayerGranted)
  // Of the balls in both of the last two snapshots, the fraction whose quantised
  // position did not change: what an at-rest (delta) encoding could leave out.
  double at_rest_fraction = 0.0;
  // ... and the fraction that moved at most 127 quanta on every axis: what a
  // delta encoding could send in 3 bytes instead of 6.
  double int8_delta_fraction = 0.0;
  std::optional<std::chrono::steady_clock::time_point> first_snapshot, last_snapshot;
};

// What the newest snapshot said.
struct WorldView {
  std::uint32_t tick = 0;
  double sim_time = 0.0;
  float steps_per_s = 0.0f;
  float load = 0.0f;
  std::uint32_t threads_stepping = 0;  // 0: the server did not say
  float time_scale = 0.0f;             // simulated seconds per wall second; 0: the server did not say
  std::uint32_t physics_steps = 0;
  bool paused = false;
  float time_scale_set = 0.0f;  // asked for; 0: the server did not say
  std::string scene;
  std::uint32_t scene_start = 0;  // +1 per scene (re)start: ball ids restart
  float max_overlap = 0.0f;       // Snapshot.max_overlap
  std::uint32_t ball_count = 0;
  std::vector<std::uint16_t> positions;  // quantised, 3 per ball (protocol/quantize.h)
  std::vector<std::uint8_t> kinds;       // by ball id, from BallKinds
  std::vector<std::uint32_t> player_ids;
  std::vector<Vec3> player_positions;
};

class Connection : public std::enable_shared_from_this<Connection> {
 public:
  Connection(boost::asio::io_context& io, std::string name, bool wants_player);

  // Connects, then sends Hello (with this protocol version unless told otherwise).
  void start(const boost::asio::ip::tcp::endpoint& server, std::uint32_t version = protocol::kProtocolVersion);
  void send(protocol::Frame frame);
  void send_ping();
  // Off: no Ack is sent, so every snapshot comes in full (as before deltas). Before start(), the Hello says so.
  void acknowledge_snapshots(bool on) { acknowledge_ = on; }
  // Reads at most this many bytes a second, as over a slow link; 0: as fast as they come.
  void limit_read_rate(double bytes_per_s) { read_rate_ = bytes_per_s; }
  // The reason is kept unless an earlier one was (the server's, or a failure's).
  void close(const std::string& reason = "closed by the client");

  bool welcomed() const { return welcomed_; }
  bool closed() const { return closed_; }
  const std::string& close_reason() const { return close_reason_; }
  std::optional<std::uint32_t> player_id() const { return player_id_; }
  // In line for a sphere: how many clients are before this one (InLine); empty when not in line.
  std::optional<std::uint32_t> ahead_in_line() const { return ahead_in_line_; }
  std::uint32_t worker_threads() const { return worker_threads_; }  // from Welcome: the most a step may use
  // The newest snapshot's tank (Welcome's until a snapshot says).
  const TankBounds& tank() const { return tank_; }
  bool may_control() const { return may_control_; }  // from Welcome, or PlayerGranted
  const std::string& control_policy() const { return control_policy_; }
  const ConnectionStats& stats() const { return stats_; }
  const WorldView& view() const { return view_; }
  // The newest position of a player sphere, if the newest snapshot has it.
  std::optional<Vec3> player_position(std::uint32_t player_id) const;
  Vec3 ball_position(std::uint32_t ball_id) const;

 private:
  void do_read();
  void handle(const wire::Message& message);
  void on_snapshot(const wire::Snapshot& s);
  void do_write();
  void fail(const std::string& reason);

  boost::asio::ip::tcp::socket socket_;
  std::string name_;
  bool wants_player_;
  protocol::FrameReader reader_{protocol::Direction::to_client};
  std::vector<std::uint8_t> read_buffer_ = std::vector<std::uint8_t>(64 * 1024);
  double read_rate_ = 0.0;                // bytes a second; 0: no limit
  boost::asio::steady_timer read_pause_;  // between reads, while the rate is limited
  std::deque<protocol::Frame> outgoing_;
  bool write_in_flight_ = false;
  bool acknowledge_ = true;
  protocol::ReceivedSnapshots received_;
  std::vector<std::uint16_t> decoded_;  // scratch: the positions of the snapshot being read

  bool welcomed_ = false;
  bool closed_ = false;
  std::string close_reason_;
  std::string farewell_;  // the Error that ends the connection, "code: message", once it came
  std::optional<std::uint32_t> player_id_;
  std::optional<std::uint32_t> ahead_in_line_;
  std::uint32_t worker_threads_ = 0;
  TankBounds tank_;
  bool may_control_ = false;
  std::string control_policy_;
  ConnectionStats stats_;
  WorldView view_;
  std::chrono::steady_clock::time_point epoch_ = std::chrono::steady_clock::now();
};

}  // namespace fishtank::client
