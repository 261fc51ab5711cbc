#pragma once
// The acceptor and the set of sessions, on the io thread.
//
//   acceptor ──► Session (one per connection) ──commands──► CommandQueue ──► physics thread
//   physics thread ──post_snapshot / post_reply──► io thread ──► the sessions
//   the sessions ──snapshot_frame──► SnapshotHistory (a frame per acknowledged base)
//
// post_* are the only members called from another thread: they hand their
// argument to the io thread with asio::post and return at once.
//
// Beyond --max-connections a newcomer gets Error(server_full) and is closed.
// When accept fails (out of file descriptors), the acceptor waits 100 ms,
// doubling up to 1.6 s, before it tries again; each such episode is logged
// once when it starts and once when accepting works again, with its count.

#include <atomic>
#include <boost/asio.hpp>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>

#include "server/net/session.h"

namespace fishtank::net {

class NetServer final : public SessionOwner {
 public:
  NetServer(boost::asio::io_context& io, ServerInfo info, CommandQueue& commands);

  // Binds and starts accepting; returns an error message, empty on success.
  std::string listen(const std::string& address, std::uint16_t port);
  boost::asio::ip::tcp::endpoint local_endpoint() const { return acceptor_.local_endpoint(); }
  // Io thread: stop accepting and close every session.
  void stop();

  // Any thread.
  void post_snapshot(SharedSnapshot snapshot);
  void post_reply(Reply reply);
  // Sessions that have been welcomed and so receive snapshots.
  const std::atomic<int>& viewers() const { return viewers_; }
  int clients() const { return clients_.load(std::memory_order_relaxed); }
  std::uint64_t total_bytes_sent() const { return bytes_sent_.load(std::memory_order_relaxed); }

  // SessionOwner (io thread)
  bool submit(Command command) override;
  void session_welcomed(Session& session) override;
  void session_closed(Session& session) override;
  void bytes_sent(std::size_t bytes) override;
  CodedSnapshot snapshot_frame(const SharedSnapshot& snapshot, std::optional<std::uint32_t> base,
                               std::optional<std::uint32_t> prior) override {
    return history_.frame(snapshot, base, prior);
  }
  // Coding of snapshot frames so far; safe to read from any thread.
  const FrameStats& frame_stats() const { return history_.stats(); }

 private:
  void do_accept();
  void admit(boost::asio::ip::tcp::socket socket);
  void refuse_full(boost::asio::ip::tcp::socket socket);
  void back_off(const boost::system::error_code& ec);

  boost::asio::io_context& io_;
  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::steady_timer accept_retry_;
  ServerInfo info_;
  CommandQueue& commands_;
  std::unordered_map<std::uint32_t, std::shared_ptr<Session>> sessions_;
  SnapshotHistory history_;
  std::uint32_t next_client_id_ = 1;
  bool stopped_ = false;
  // The current episode of failed accepts, and of newcomers refused while full.
  std::uint64_t failed_accepts_ = 0;
  std::chrono::steady_clock::duration accept_backoff_{};
  std::chrono::steady_clock::time_point failing_since_;
  std::uint64_t refused_while_full_ = 0;
  std::atomic<int> viewers_{0};
  std::atomic<int> clients_{0};
  std::atomic<std::uint64_t> bytes_sent_{0};
};

}  // namespace fishtank::net
