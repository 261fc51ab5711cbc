#include "server/net/tcp_session.h"

#include "server/net/plain_http.h"

namespace fishtank::net {

namespace asio = boost::asio;

namespace {
// A frame's buffer starts at this and doubles as its bytes arrive.
constexpr std::size_t kFirstChunkBytes = 4096;

// The first four bytes of an HTTP request: a browser given this port instead of the web viewer's.
bool starts_http_request(const std::array<std::uint8_t, protocol::kLengthPrefixBytes>& first) {
  const std::string text(first.begin(), first.end());
  for (const char* method : {"GET ", "HEAD", "POST", "PUT ", "OPTI", "DELE", "PATC", "CONN", "TRAC"})
    if (text == method) return true;
  return false;
}
}  // namespace

TcpSession::TcpSession(asio::ip::tcp::socket socket, const asio::ip::tcp::endpoint& peer, std::uint32_t id,
                       const ServerInfo& info, SessionOwner& owner)
    : Session(socket.get_executor(), peer, id, info, owner), socket_(std::move(socket)) {
  boost::system::error_code ignored;
  socket_.set_option(asio::ip::tcp::no_delay(true), ignored);  // small replies (Pong) should not wait for Nagle
}

void TcpSession::do_read() {
  asio::async_read(socket_, asio::buffer(header_),
                   [this, self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                     if (ec) return on_error(ec, "disconnected");
                     received_bytes();
                     if (ending()) return do_drain();
                     if (!hello_received() && starts_http_request(header_)) {
                       answer_browser();
                       return read_on();  // the rest of the request is drained, as any ending session's
                     }
                     std::uint32_t body_bytes = 0;
                     const protocol::DecodeResult length = check_length_prefix(header_.data(), &body_bytes);
                     if (!length.ok()) {
                       stream_broken(length);
                       return read_on();
                     }
                     frame_bytes_ = protocol::kLengthPrefixBytes + body_bytes;
                     incoming_.assign(header_.begin(), header_.end());
                     do_read_body();
                   });
}

void TcpSession::answer_browser() {
  const std::uint16_t web = owner().listening_port(/*web=*/true);
  const std::string body =
      "This port speaks Fishtank's own protocol, for fishtank-viewer, fishtank-client and the Python client.\n" +
      (web ? "The browser viewer is on port " + std::to_string(web) + " of this machine: put " + std::to_string(web) +
                 " in the address instead.\n"
           : std::string("This server serves no browser viewer (it was started with --no-web).\n"));
  const std::string response = plain_http_response("400 Bad Request", body);
  answer_in_kind_and_close(std::vector<std::uint8_t>(response.begin(), response.end()),
                           "an HTTP request on the TCP port: told the browser the web viewer's port");
}

// The buffer doubles as the bytes come in, so a peer that announces a large
// frame and stalls holds about twice what it actually sent, not what it announced.
void TcpSession::do_read_body() {
  const std::size_t have = incoming_.size();
  const std::size_t chunk = std::min(frame_bytes_ - have, std::max(have, kFirstChunkBytes));
  incoming_.resize(have + chunk);
  asio::async_read(socket_, asio::buffer(incoming_.data() + have, chunk),
                   [this, self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                     if (ec) return on_error(ec, "disconnected mid-frame");
                     received_bytes();
                     if (ending()) return do_drain();
                     if (incoming_.size() < frame_bytes_) return do_read_body();
                     frame_received(incoming_.data(), incoming_.size());
                     // A large frame's buffer is not kept for the small ones that follow.
                     if (incoming_.capacity() > 4 * kFirstChunkBytes) protocol::Frame().swap(incoming_);
                     read_on();
                   });
}

// A session that is ending reads and drops what the peer still sends: closing
// with unread bytes would reset the connection, and the peer could lose the
// Error that says why. The peer's close, or the grace period, ends it.
void TcpSession::do_drain() {
  if (closed()) return;
  incoming_.resize(kFirstChunkBytes);
  socket_.async_read_some(asio::buffer(incoming_),
                          [this, self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                            if (ec) return on_error(ec, "disconnected by the server");
                            do_drain();
                          });
}

void TcpSession::write_frames(std::vector<asio::const_buffer> frames) {
  asio::async_write(socket_, frames, [this, self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
    frames_written(ec, n);
  });
}

void TcpSession::send_farewell() {
  boost::system::error_code ignored;
  socket_.shutdown(asio::ip::tcp::socket::shutdown_send, ignored);
}

void TcpSession::close_transport() {
  boost::system::error_code ignored;
  socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
  socket_.close(ignored);
}

}  // namespace fishtank::net
