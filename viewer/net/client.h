#pragma once
// The viewer's connection to fishtank-server, run by its own thread so that a
// slow or lost server never stalls a frame (DESIGN "Processes and threads").
//
//   net thread (Boost.Asio)                          render thread
//   connect ► Hello ► read frames ──decoded──► SnapshotBuffer ──► interpolate, draw
//                  ◄ Ack per snapshot decoded (the server then sends deltas against it)
//                  ◄ PlayerInput every 1/30 s ◄── set_velocity()
//                  ◄ AddBalls                 ◄── add_balls()
//                  ◄ Pause, Step, Reset, ...  ◄── send_command()
//                  ◄ Ping every second; Pong gives the round trip
//   any error ► "lost", wait a second, connect again (forever)
//
// Everything below the public functions runs on the net thread only; the
// public functions may be called from any thread.

#include <boost/asio.hpp>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "protocol/frame_codec.h"
#include "protocol/received_snapshots.h"
#include "viewer/net/snapshot_buffer.h"

namespace fishtank::viewer {

struct ConnectionStatus {
  enum class State { connecting, connected, lost };
  State state = State::connecting;
  std::string endpoint;                    // host:port, for messages
  std::string last_error;                  // why the last connection ended or failed
  int attempts = 0;                        // connection attempts since the last Welcome
  std::shared_ptr<const ServerInfo> info;  // from Welcome; null before it
  float snapshots_per_s = 0.0f;            // each measured over the last second
  float bytes_per_s = 0.0f;
  float rtt_ms = -1.0f;  // negative until the first Pong
  std::string notice;    // the server's last Error message, for the HUD
  double notice_time = -1.0;
};

class NetClient {
 public:
  NetClient(std::string host, std::string port, bool wants_player, SnapshotBuffer& snapshots);
  ~NetClient();  // stops the thread and closes the connection
  NetClient(const NetClient&) = delete;
  NetClient& operator=(const NetClient&) = delete;

  void set_velocity(Vec3 velocity);
  void add_balls(std::uint32_t count);
  // Off: the server sends no snapshots until on again (a minimised window draws nothing).
  void set_watching(bool on);
  // Sends a frame as it is (the sandbox's controls), if connected.
  void send_command(protocol::Frame frame);
  ConnectionStatus status() const;

 private:
  void do_connect();
  void do_read_prefix();
  void do_read_body(std::uint32_t body_bytes);
  void do_write();
  void send(protocol::Frame frame);
  void on_frame();
  void on_welcome(const wire::Welcome& w);
  void on_ball_kinds(const wire::BallKinds& k);
  void on_snapshot(const wire::Snapshot& s);
  void lose(const std::string& why);
  void every_input_tick();
  void every_second();
  template <class F>
  void update_status(F&& f) {
    std::lock_guard lock(status_mutex_);
    f(status_);
  }
  // The render thread holds ServerInfo read-only: a change publishes a changed copy, with a notice if given.
  void change_info(const std::function<void(ServerInfo&)>& change, std::string notice = {});

  std::string host_, port_;
  bool wants_player_;
  SnapshotBuffer& snapshots_;

  boost::asio::io_context io_;
  boost::asio::ip::tcp::resolver resolver_{io_};
  boost::asio::ip::tcp::socket socket_{io_};
  boost::asio::steady_timer retry_timer_{io_};
  boost::asio::steady_timer input_timer_{io_};
  boost::asio::steady_timer second_timer_{io_};
  // Bumped whenever a connection ends, so handlers of an old socket that
  // complete late recognise themselves as stale.
  std::uint64_t generation_ = 0;
  bool connected_ = false;  // Welcome received on the current connection
  std::string farewell_;    // the Error that ends the current connection, "code: message", once it came
  bool watching_ = true;    // what the server was last asked (Watching); every connection starts on
  std::uint8_t prefix_[protocol::kLengthPrefixBytes] = {};
  protocol::Frame frame_;
  std::deque<protocol::Frame> write_queue_;  // front is in flight
  std::shared_ptr<const ServerInfo> info_;
  std::shared_ptr<const std::vector<std::uint8_t>> kinds_;
  protocol::ReceivedSnapshots received_;  // bases for delta snapshots
  std::uint32_t input_sequence_ = 0;
  std::uint64_t snapshots_this_second_ = 0;
  std::uint64_t bytes_this_second_ = 0;
  double second_started_ = 0.0;
  double ping_epoch_ = 0.0;

  mutable std::mutex status_mutex_;
  ConnectionStatus status_;
  mutable std::mutex velocity_mutex_;
  Vec3 velocity_;

  std::thread thread_;  // last: started once everything above exists
};

}  // namespace fishtank::viewer
