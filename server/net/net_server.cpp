#include "server/net/net_server.h"

#include <spdlog/spdlog.h>

#include "server/net/plain_http.h"
#include "server/net/tcp_session.h"
#include "server/net/web_session.h"

namespace fishtank::net {

namespace asio = boost::asio;
using asio::ip::tcp;

namespace {
constexpr auto kFirstAcceptBackoff = std::chrono::milliseconds(100);
constexpr auto kMaxAcceptBackoff = std::chrono::milliseconds(1600);
}  // namespace

NetServer::NetServer(asio::io_context& io, ServerInfo info, CommandQueue& commands)
    : io_(io), tcp_(io), web_(io), info_(std::move(info)), commands_(commands) {}

std::string NetServer::bind(Listener& listener, const std::string& address, std::uint16_t port,
                            const std::string& in_use_hint) {
  boost::system::error_code ec;
  const asio::ip::address ip = asio::ip::make_address(address, ec);
  if (ec) return "--bind '" + address + "' is not an IP address";
  const tcp::endpoint endpoint(ip, port);
  tcp::acceptor& acceptor = listener.acceptor;
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec == asio::error::address_in_use)
    return "cannot listen on " + address + ":" + std::to_string(port) +
           ": another program (another fishtank-server?) holds that port; " + in_use_hint;
  if (ec == boost::system::errc::address_not_available)
    return "cannot listen on " + address + ":" + std::to_string(port) +
           ": that is not an address of this machine; --bind 0.0.0.0 listens on all of them";
  if (ec) return "cannot listen on " + address + ":" + std::to_string(port) + ": " + ec.message();
  return {};
}

std::string NetServer::listen(const std::string& address, std::uint16_t port) {
  if (std::string error = bind(tcp_, address, port,
                               "stop it, or choose another with --port P (--port 0 picks a free one and prints it)");
      !error.empty())
    return error;
  do_accept(tcp_, Kind::tcp);
  return {};
}

std::string NetServer::listen_web(const std::string& address, std::uint16_t port, const std::string& web_root) {
  if (std::string error = bind(web_, address, port,
                               "choose another port for the web viewer with --web-port (0: any free one) or turn it "
                               "off with --no-web");
      !error.empty())
    return error;
  files_.emplace(web_root);
  do_accept(web_, Kind::web);
  return {};
}

void NetServer::do_accept(Listener& listener, Kind kind) {
  listener.acceptor.async_accept([this, &listener, kind](boost::system::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted || stopped_) return;
    // Out of file descriptors and the like: retrying at once would spin.
    if (ec) return back_off(listener, kind, ec);
    if (listener.failed_accepts > 0) {
      spdlog::info("accepting connections again after {} failed attempts over {:.1f} s", listener.failed_accepts,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - listener.failing_since).count());
      listener.failed_accepts = 0;
    }
    admit(std::move(socket), kind);
    do_accept(listener, kind);
  });
}

void NetServer::admit(tcp::socket socket, Kind kind) {
  boost::system::error_code ec;
  const tcp::endpoint peer = socket.remote_endpoint(ec);
  if (ec) return;  // gone already; the socket closes here
  if (!make_room(peer.address())) return refuse_full(std::move(socket), kind);
  if (refused_while_full_ > 0) {
    spdlog::info("admitting clients again; {} were refused while {} were connected (--max-connections)",
                 refused_while_full_, info_.limits.max_connections);
    refused_while_full_ = 0;
  }
  const std::uint32_t id = next_client_id_++;
  std::shared_ptr<Session> session;
  if (kind == Kind::web)
    session = std::make_shared<WebSession>(std::move(socket), peer, id, info_, *this, *files_);
  else
    session = std::make_shared<TcpSession>(std::move(socket), peer, id, info_, *this);
  sessions_.emplace(id, session);
  pending_.insert(id);
  pending_by_address_[peer.address()].insert(id);
  clients_.store(static_cast<int>(sessions_.size()), std::memory_order_relaxed);
  session->start();
}

bool NetServer::make_room(const asio::ip::address& address) {
  const ClientLimits& limits = info_.limits;
  if (auto mine = pending_by_address_.find(address);
      mine != pending_by_address_.end() && mine->second.size() >= limits.max_pending_per_address) {
    evict(*mine->second.begin(), "evicted: " + std::to_string(limits.max_pending_per_address) +
                                     " newer connections from your address have not said Hello either "
                                     "(--max-pending-per-address)");
    return true;
  }
  if (sessions_.size() < limits.max_connections) return true;
  if (pending_.empty()) return false;
  evict(*pending_.begin(), "evicted: the server has its " + std::to_string(limits.max_connections) +
                               " clients (--max-connections) and this connection is the oldest that has not "
                               "said Hello");
  return true;
}

void NetServer::evict(std::uint32_t id, const std::string& why) {
  const auto it = sessions_.find(id);
  const std::shared_ptr<Session> session = it->second;
  sessions_.erase(it);
  forget_pending(id, session->address());
  leaving_.emplace(id, session);
  clients_.store(static_cast<int>(sessions_.size()), std::memory_order_relaxed);
  session->evict(why);
}

void NetServer::forget_pending(std::uint32_t id, const asio::ip::address& address) {
  if (pending_.erase(id) == 0) return;
  const auto mine = pending_by_address_.find(address);
  mine->second.erase(id);
  if (mine->second.empty()) pending_by_address_.erase(mine);
}

void NetServer::refuse_full(tcp::socket socket, Kind kind) {
  if (refused_while_full_++ == 0)
    spdlog::warn("{} clients connected, all past Hello (--max-connections): refusing newcomers with server_full",
                 info_.limits.max_connections);
  auto peer = std::make_shared<tcp::socket>(std::move(socket));
  const std::string why = "the server already has its " + std::to_string(info_.limits.max_connections) +
                          " clients (--max-connections); try again later";
  const std::string http = plain_http_response("503 Service Unavailable", why + "\n");
  auto frame =
      std::make_shared<protocol::Frame>(kind == Kind::web ? protocol::Frame(http.begin(), http.end())
                                                          : protocol::encode_error(wire::ErrorCode::server_full, why));
  // A few hundred bytes at most: the socket's buffer takes them whether or not the peer reads.
  asio::async_write(*peer, asio::buffer(*frame), [peer, frame](boost::system::error_code, std::size_t) {
    boost::system::error_code ignored;
    peer->shutdown(tcp::socket::shutdown_both, ignored);
    peer->close(ignored);
  });
}

void NetServer::back_off(Listener& listener, Kind kind, const boost::system::error_code& ec) {
  const auto now = std::chrono::steady_clock::now();
  if (listener.failed_accepts++ == 0) {
    listener.failing_since = now;
    listener.backoff = kFirstAcceptBackoff;
    spdlog::warn("accept failed: {}; retrying after {} ms, then less often, until it works", ec.message(),
                 std::chrono::duration_cast<std::chrono::milliseconds>(listener.backoff).count());
  } else {
    listener.backoff = std::min<std::chrono::steady_clock::duration>(2 * listener.backoff, kMaxAcceptBackoff);
  }
  listener.retry.expires_after(listener.backoff);
  listener.retry.async_wait([this, &listener, kind](boost::system::error_code wait_ec) {
    if (!wait_ec && !stopped_) do_accept(listener, kind);
  });
}

void NetServer::stop(const std::string& why) {
  if (stopped_) return;
  stopped_ = true;
  boost::system::error_code ignored;
  for (Listener* listener : {&tcp_, &web_}) {
    listener->acceptor.close(ignored);
    listener->retry.cancel();
  }
  // close() calls session_closed(), which erases from these maps: iterate over copies.
  for (const auto& sessions : {sessions_, leaving_})
    for (const auto& [id, session] : sessions) session->say_server_stopping(why);
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

void NetServer::session_said_hello(Session& session) { forget_pending(session.id(), session.address()); }

void NetServer::session_welcomed(Session&) { viewers_.fetch_add(1, std::memory_order_relaxed); }

void NetServer::session_closed(Session& session) {
  if (session.welcomed()) viewers_.fetch_sub(1, std::memory_order_relaxed);
  // Removes the player sphere, if any; a client that never said Hello has none, and Leave is harmless.
  commands_.push(Command{session.id(), LeaveCommand{}});
  forget_pending(session.id(), session.address());
  sessions_.erase(session.id());
  leaving_.erase(session.id());
  clients_.store(static_cast<int>(sessions_.size()), std::memory_order_relaxed);
}

void NetServer::bytes_sent(std::size_t bytes) { bytes_sent_.fetch_add(bytes, std::memory_order_relaxed); }

}  // namespace fishtank::net
