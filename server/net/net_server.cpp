#include "server/net/net_server.h"

#include <spdlog/spdlog.h>

namespace fishtank::net {

namespace asio = boost::asio;
using asio::ip::tcp;

NetServer::NetServer(asio::io_context& io, ServerInfo info, CommandQueue& commands)
    : io_(io), acceptor_(io), info_(std::move(info)), commands_(commands) {}

std::string NetServer::listen(const std::string& address, std::uint16_t port) {
  boost::system::error_code ec;
  const asio::ip::address ip = asio::ip::make_address(address, ec);
  if (ec) return "--bind '" + address + "' is not an IP address";
  const tcp::endpoint endpoint(ip, port);
  acceptor_.open(endpoint.protocol(), ec);
  if (!ec) acceptor_.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor_.bind(endpoint, ec);
  if (!ec) acceptor_.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) return "cannot listen on " + address + ":" + std::to_string(port) + ": " + ec.message();
  do_accept();
  return {};
}

void NetServer::do_accept() {
  acceptor_.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted || stopped_) return;
    if (ec) {
      // Out of file descriptors and the like: this connection fails, the server goes on.
      spdlog::warn("accept failed: {}", ec.message());
    } else {
      auto session = std::make_shared<Session>(std::move(socket), next_client_id_++, info_, *this);
      sessions_.emplace(session->id(), session);
      clients_.store(static_cast<int>(sessions_.size()), std::memory_order_relaxed);
      session->start();
    }
    do_accept();
  });
}

void NetServer::stop() {
  stopped_ = true;
  boost::system::error_code ignored;
  acceptor_.close(ignored);
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
