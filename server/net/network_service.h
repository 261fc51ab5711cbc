#pragma once
// Everything the server's network side needs, wired together: the io thread
// running Boost.Asio (acceptor, sessions, SIGINT/SIGTERM), the command queue,
// and the PhysicsLink that the physics thread calls at step boundaries.
//
//   physics thread (run_realtime)             io thread (this class's)
//   ─────────────────────────────             ───────────────────────────────
//   at_step_boundary() ─ apply commands ◄──── CommandQueue ◄── sessions
//                      └ encode snapshot ───► post ──► NetServer ──► sessions
//   status()  (once per status interval)      signal_set ──► stop flag

#include <atomic>
#include <boost/asio.hpp>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "server/net/net_server.h"
#include "server/net/physics_link.h"

namespace fishtank::net {

struct NetOptions {
  std::string bind = "127.0.0.1";
  std::uint16_t port = 7878;  // 0: the system picks a free port (printed by start())
  bool web = true;            // the web viewer: HTTP and WebSocket on web_port, at the same address
  std::uint16_t web_port = 8080;
  std::string web_root;  // the page's folder
  PhysicsLinkOptions link;
};

class NetworkService {
 public:
  // stop is set by SIGINT or SIGTERM. control and scene are the physics
  // thread's, changed by clients' commands at step boundaries.
  NetworkService(const NetOptions& options, ServerInfo info, RunControl& control, ActiveScene& scene,
                 std::atomic<bool>& stop);
  // Stops the io thread once every client is told (stop()) or its grace has passed.
  ~NetworkService();

  // Binds, prints "listening on ADDRESS:PORT" on stderr (and "web viewer on
  // http://ADDRESS:PORT/" unless the web side is off), starts the io thread.
  // Returns an error message, empty on success.
  std::string start();

  // Physics thread.
  void at_step_boundary(World& world, const LoopStatus& status) { link_.at_step_boundary(world, status); }
  // Physics thread: clients, bytes/s out and the network's CPU cost since the last call.
  std::string status();
  // Once the physics loop has returned: no newcomers, and every client is told why it ends (an Error, server_stopping),
  // while the final files are written.
  void stop(const std::string& why);

 private:
  void await_second_signal(int first);

  NetOptions options_;
  boost::asio::io_context io_;
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> work_;
  boost::asio::signal_set signals_;
  CommandQueue commands_;
  NetServer server_;
  PhysicsLink link_;
  std::thread io_thread_;

  // status() window
  std::chrono::steady_clock::time_point last_status_ = std::chrono::steady_clock::now();
  std::uint64_t last_bytes_ = 0;
  std::uint64_t last_skipped_ = 0;
  double last_io_cpu_ = 0.0, last_process_cpu_ = 0.0, last_encode_seconds_ = 0.0, last_encode_cpu_seconds_ = 0.0;
  std::uint64_t last_encoded_ = 0;
  std::uint64_t last_frames_ = 0, last_keyframes_ = 0, last_frame_bytes_ = 0;
  double last_coding_seconds_ = 0.0;
};

}  // namespace fishtank::net
