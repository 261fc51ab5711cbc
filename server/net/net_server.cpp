#include "server/net/net_server.h"

#include <spdlog/spdlog.h>

namespace fishtank::net {

namespace asio = boost::asio;
using asio::ip::tcp;

namespace {
constexpr auto kFirstAcceptBackoff = std::chrono::milliseconds(100);
constexpr auto kMaxAcceptBackoff = std::chrono::milliseconds(1600);
}  // namespace

NetServer::NetServer(asio::io_context& io, ServerInfo info, CommandQueue& commands)
    : io_(io), acceptor_(io), accept_retry_(io), info_(std::move(info)), commands_(commands) {}

std::string NetServer::listen(const std::string& address, std::uint16_t port) {
  boost::system::error_code ec;
  const asio::ip::address ip = asio::ip::make_address(address, ec);
  if (ec) return "--bind '" + address + "' is not an IP address";
  const tcp::endpoint endpoint(ip, port);
  acceptor_.open(endpoint.protocol(), ec);
  if (!ec) acceptor_.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor_.bind(endpoint, ec);
  if (!ec) acceptor_.listen(asio::socket_base::max_listen_connections, ec);
  if (ec == asio::error::address_in_use)
    return "cannot listen on " + address + ":" + std::to_string(port) +
           ": another program (another fishtank-server?) holds that port; stop it, or choose another with "
           "--port P (--port 0 picks a free one and prints it)";
  if (ec) return "cannot listen on " + address + ":" + std::to_string(port) + ": " + ec.message();
  do_accept();
  return {};
}

void NetServer::do_accept() {
  acceptor_.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted || stopped_) return;
    // Out of file descriptors and the like: retrying at once would spin.
    if (ec) return back_off(ec);
    if (failed_accepts_ > 0) {
      spdlog::info("accepting connections again after {} failed attempts over {:.1f} s", failed_accepts_,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - failing_since_).count());
      failed_accepts_ = 0;
    }
    if (sessions_.size() >= info_.limits.max_connections)
      refuse_full(std::move(socket));
    else
      admit(std::move(socket));
    do_accept();
  });
}

void NetServer::admit(tcp::socket socket) {
  if (refused_while_full_ > 0) {
    spdlog::info("admitting clients again; {} were refused while {} were connected (--max-connections)",
                 refused_while_full_, info_.limits.max_connections);
    refused_while_full_ = 0;
  }
  auto session = std::make_shared<Session>(std::move(socket), next_client_id_++, info_, *this);
  sessions_.emplace(session->id(), session);
  clients_.store(static_cast<int>(sessions_.size()), std::memory_order_relaxed);
  session->start();
}

void NetServer::refuse_full(tcp::socket socket) {
  if (refused_while_full_++ == 0)
    spdlog::warn("{} clients connected (--max-connections): refusing newcomers with server_full",
                 info_.limits.max_connections);
  auto peer = std::make_shared<tcp::socket>(std::move(socket));
  auto frame = std::make_shared<protocol::Frame>(protocol::encode_error(
      wire::ErrorCode::server_full, "the server already has its " + std::to_string(info_.limits.max_connections) +
                                        " clients (--max-connections); try again later"));
  // A few dozen bytes: the socket's buffer takes them whether or not the peer reads.
  asio::async_write(*peer, asio::buffer(*frame), [peer, frame](boost::system::error_code, std::size_t) {
    boost::system::error_code ignored;
    peer->shutdown(tcp::socket::shutdown_both, ignored);
    peer->close(ignored);
  });
}

void NetServer::back_off(const boost::system::error_code& ec) {
  const auto now = std::chrono::steady_clock::now();
  if (failed_accepts_++ == 0) {
    failing_since_ = now;
    accept_backoff_ = kFirstAcceptBackoff;
    spdlog::warn("accept failed: {}; retrying after {} ms, then less often, until it works", ec.message(),
                 std::chrono::duration_cast<std::chrono::milliseconds>(accept_backoff_).count());
  } else {
    accept_backoff_ = std::min<std::chrono::steady_clock::duration>(2 * accept_backoff_, kMaxAcceptBackoff);
  }
  accept_retry_.expires_after(accept_backoff_);
  accept_retry_.async_wait([this](boost::system::error_code wait_ec) {
    if (!wait_ec && !stopped_) do_accept();
  });
}

void NetServer::stop() {
  stopped_ = true;
  boost::system::error_code ignored;
  acceptor_.close(ignored);
  accept_retry_.cancel();
  // close() calls session_closed(), which erases from sessions_: iterate over a copy.
  const auto sessions = sessions_;
  for (const auto& [id, session] : sessions) session->close("server shutting down");
}

void NetServer::post_snapshot(SharedSnapshot snapshot) {
  asio::post(io_, [this, snapshot = std::move(snapshot)] {
    history_.publish(snapshot);
    // offer_snapshot() never closes a session synchronously, so sessions_ is stable here.
    for (const auto& [id, session] : sessions_) session->offer_snapshot(snapshot);
  });
}

void NetServer::post_reply(Reply reply) {
  asio::post(io_, [this, reply = std::move(reply)] {
    auto it = sessions_.find(reply.client_id);
    if (it == sessions_.end()) return;                    // gone before the physics answered
    const std::shared_ptr<Session> session = it->second;  // deliver() may close it, which erases it
    session->deliver(reply);
  });
}

bool NetServer::submit(Command command) { return commands_.push(std::move(command)); }

void NetServer::session_welcomed(Session&) { viewers_.fetch_add(1, std::memory_order_relaxed); }

void NetServer::session_closed(Session& session) {
  if (session.welcomed()) viewers_.fetch_sub(1, std::memory_order_relaxed);
  // Removes the player sphere, if any; a client that never said Hello has none, and Leave is harmless.
  commands_.push(Command{session.id(), LeaveCommand{}});
  sessions_.erase(session.id());
  clients_.store(static_cast<int>(sessions_.size()), std::memory_order_relaxed);
}

void NetServer::bytes_sent(std::size_t bytes) { bytes_sent_.fetch_add(bytes, std::memory_order_relaxed); }

}  // namespace fishtank::net
