#pragma once
// The acceptors and the set of sessions, on the io thread.
//
//   TCP acceptor ──► TcpSession ─┐
//   web acceptor ──► WebSession ─┴─► (Session) ──commands──► CommandQueue ──► physics thread
//   physics thread ──post_snapshot / post_reply──► io thread ──► the sessions
//   the sessions ──snapshot_frame──► SnapshotHistory (a frame per acknowledged base)
//
// post_* are the only members called from another thread: they hand their
// argument to the io thread with asio::post and return at once.
//
// Admission, so that strangers cannot keep an honest client out: a newcomer
// from an address that already has --max-pending-per-address connections
// without Hello evicts the oldest of them; a newcomer to a full table
// (--max-connections) evicts the oldest connection of all that has not said
// Hello. Evicted ones get Error(server_full) and leave. Sessions that said
// Hello are never evicted: only when every place is theirs is a newcomer
// refused with server_full.
// When accept fails (out of file descriptors), the acceptor waits 100 ms,
// doubling up to 1.6 s, before it tries again; each such episode is logged
// once when it starts and once when accepting works again, with its count.

#include <atomic>
#include <boost/asio.hpp>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>

#include "server/net/session.h"
#include "server/net/static_files.h"

namespace fishtank::net {

class NetServer final : public SessionOwner {
 public:
  NetServer(boost::asio::io_context& io, ServerInfo info, CommandQueue& commands);

  // Binds and starts accepting; returns an error message, empty on success.
  std::string listen(const std::string& address, std::uint16_t port);
  // The same for the web viewer: HTTP with static files from web_root, and WebSocket at /ws.
  std::string listen_web(const std::string& address, std::uint16_t port, const std::string& web_root);
  boost::asio::ip::tcp::endpoint local_endpoint() const { return tcp_.acceptor.local_endpoint(); }
  boost::asio::ip::tcp::endpoint web_endpoint() const { return web_.acceptor.local_endpoint(); }
  const StaticFiles* static_files() const { return files_ ? &*files_ : nullptr; }
  // Io thread: stop accepting, and tell every session why before it closes (Session::say_server_stopping).
  void stop(const std::string& why);

  // Any thread.
  void post_snapshot(SharedSnapshot snapshot);
  void post_reply(Reply reply);
  // Sessions that have been welcomed and so receive snapshots.
  const std::atomic<int>& viewers() const { return viewers_; }
  int clients() const { return clients_.load(std::memory_order_relaxed); }
  std::uint64_t total_bytes_sent() const { return bytes_sent_.load(std::memory_order_relaxed); }
  std::uint64_t total_snapshots_skipped() const { return snapshots_skipped_.load(std::memory_order_relaxed); }

  // SessionOwner (io thread)
  bool submit(Command command) override;
  void session_said_hello(Session& session) override;
  void session_welcomed(Session& session) override;
  void session_closed(Session& session) override;
  void bytes_sent(std::size_t bytes) override;
  std::uint16_t listening_port(bool web) const override {
    const boost::asio::ip::tcp::acceptor& acceptor = (web ? web_ : tcp_).acceptor;
    return acceptor.is_open() ? acceptor.local_endpoint().port() : 0;
  }
  void snapshot_skipped() override { snapshots_skipped_.fetch_add(1, std::memory_order_relaxed); }
  CodedSnapshot snapshot_frame(const SharedSnapshot& snapshot, std::optional<std::uint32_t> base,
                               std::optional<std::uint32_t> prior,
                               const std::function<bool(std::uint32_t)>& keeps) override {
    return history_.frame(snapshot, base, prior, keeps);
  }
  // Coding of snapshot frames so far; safe to read from any thread.
  const FrameStats& frame_stats() const { return history_.stats(); }

 private:
  enum class Kind { tcp, web };
  struct Listener {
    explicit Listener(boost::asio::io_context& io) : acceptor(io), retry(io) {}
    boost::asio::ip::tcp::acceptor acceptor;
    boost::asio::steady_timer retry;
    // The current episode of failed accepts.
    std::uint64_t failed_accepts = 0;
    std::chrono::steady_clock::duration backoff{};
    std::chrono::steady_clock::time_point failing_since;
  };

  // in_use_hint: what to do when another program holds the port.
  static std::string bind(Listener& listener, const std::string& address, std::uint16_t port,
                          const std::string& in_use_hint);
  void do_accept(Listener& listener, Kind kind);
  void back_off(Listener& listener, Kind kind, const boost::system::error_code& ec);
  void admit(boost::asio::ip::tcp::socket socket, Kind kind);
  // Frees a place for a newcomer from `address`; false when every place belongs to a session that said Hello.
  bool make_room(const boost::asio::ip::address& address);
  void evict(std::uint32_t id, const std::string& why);
  void forget_pending(std::uint32_t id, const boost::asio::ip::address& address);
  void refuse_full(boost::asio::ip::tcp::socket socket, Kind kind);

  boost::asio::io_context& io_;
  Listener tcp_;
  Listener web_;
  std::optional<StaticFiles> files_;
  ServerInfo info_;
  CommandQueue& commands_;
  // Every session that holds a place (counted against --max-connections) ...
  std::unordered_map<std::uint32_t, std::shared_ptr<Session>> sessions_;
  // ... those of them without Hello, oldest first (ids grow), in all and by address ...
  std::set<std::uint32_t> pending_;
  std::map<boost::asio::ip::address, std::set<std::uint32_t>> pending_by_address_;
  // ... and the evicted, which hold no place while their Error goes out.
  std::unordered_map<std::uint32_t, std::shared_ptr<Session>> leaving_;
  SnapshotHistory history_;
  std::uint32_t next_client_id_ = 1;
  bool stopped_ = false;
  std::uint64_t refused_while_full_ = 0;  // newcomers refused while every place was taken
  std::atomic<int> viewers_{0};
  std::atomic<int> clients_{0};
  std::atomic<std::uint64_t> bytes_sent_{0};
  std::atomic<std::uint64_t> snapshots_skipped_{0};
};

}  // namespace fishtank::net
