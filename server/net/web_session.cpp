#include "server/net/web_session.h"

#include <spdlog/spdlog.h>

namespace fishtank::net {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;

namespace {
// A message larger than the buffer's keeps its memory only until the next read.
constexpr std::size_t kKeptBufferBytes = 16 * 1024;
}  // namespace

WebSession::WebSession(asio::ip::tcp::socket socket, const asio::ip::tcp::endpoint& peer, std::uint32_t id,
                       const ServerInfo& info, SessionOwner& owner, const StaticFiles& files)
    : Session(socket.get_executor(), peer, id, info, owner), files_(files), http_(std::move(socket)) {
  boost::system::error_code ignored;
  http_.socket().set_option(asio::ip::tcp::no_delay(true), ignored);
}

void WebSession::do_read_request() {
  parser_.emplace();
  parser_->header_limit(kMaxHeaderBytes);
  parser_->body_limit(kMaxRequestBodyBytes);
  http::async_read(http_, buffer_, *parser_, [this, self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec == http::error::end_of_stream) return close("disconnected");
    if (ec == http::error::header_limit)
      return respond_text(http::status::request_header_fields_too_large,
                          "<p>431: the request's header is over " + std::to_string(kMaxHeaderBytes) + " bytes.</p>\n",
                          false);
    if (ec == http::error::body_limit)
      return respond_text(http::status::payload_too_large,
                          "<p>413: the request's body is over " + std::to_string(kMaxRequestBodyBytes) +
                              " bytes; this server only serves files (GET, HEAD).</p>\n",
                          false);
    if (ec && reads_as_fishtank_frame()) return answer_fishtank_client();
    if (ec) return on_error(ec, "disconnected");
    received_bytes();
    on_request();
  });
}

bool WebSession::reads_as_fishtank_frame() const {
  // A size-prefixed FlatBuffer: the length, the root's offset, then the file identifier.
  const auto* bytes = static_cast<const std::uint8_t*>(buffer_.data().data());
  const std::size_t at = protocol::kLengthPrefixBytes + 4, size = buffer_.size();
  return size >= at + 4 && std::equal(bytes + at, bytes + at + 4, protocol::kFileIdentifier);
}

void WebSession::answer_fishtank_client() {
  const std::uint16_t tcp = owner().listening_port(/*web=*/false);
  auto error = std::make_shared<protocol::Frame>(
      protocol::encode_error(wire::ErrorCode::wrong_port,
                             "this is fishtank-server's web port, for browsers; fishtank-viewer, "
                             "fishtank-client and the Python client connect to its port " +
                                 std::to_string(tcp) + " (the 'listening on' line of its log)"));
  // Written as is, not through the Session: a connection before the upgrade carries no frames.
  asio::async_write(http_.socket(), asio::buffer(*error),
                    [this, self = shared_from_this(), error](beast::error_code ec, std::size_t) {
                      if (ec) return on_error(ec, "disconnected");
                      beast::error_code ignored;
                      http_.socket().shutdown(asio::ip::tcp::socket::shutdown_send, ignored);
                      drain_before_upgrade();
                    });
}

// The peer's close ends it (--hello-timeout at the latest): closing with its bytes unread would reset the
// connection, and the peer could lose the Error that says why.
void WebSession::drain_before_upgrade() {
  buffer_.consume(buffer_.size());
  http_.socket().async_read_some(buffer_.prepare(1024),
                                 [this, self = shared_from_this()](beast::error_code ec, std::size_t) {
                                   if (ec)
                                     return on_error(ec, "a Fishtank client on the web port: told it the TCP port");
                                   drain_before_upgrade();
                                 });
}

void WebSession::on_request() {
  const Request& request = parser_->get();
  const std::string_view target(request.target().data(), request.target().size());
  const std::optional<std::string> path = decode_target_path(target);
  if (websocket::is_upgrade(request)) {
    if (path && *path == "/ws") return upgrade();
    return respond_text(http::status::not_found, "<p>404: WebSocket connections upgrade at /ws only.</p>\n",
                        request.keep_alive());
  }
  if (path && *path == "/ws") {  // someone opened the socket's address in a browser, or fetched it with curl
    http::response<http::string_body> response{http::status::upgrade_required, request.version()};
    response.set(http::field::upgrade, "websocket");  // what the status asks for (RFC 9110)
    response.set(http::field::content_type, "text/html; charset=utf-8");
    response.body() =
        "<p>426: /ws is the viewer's WebSocket, which a browser opens from the page; open / instead.</p>\n";
    response.keep_alive(request.keep_alive());
    response.prepare_payload();
    return respond(std::move(response));
  }
  if (request.method() != http::verb::get && request.method() != http::verb::head) {
    http::response<http::string_body> response{http::status::method_not_allowed, request.version()};
    response.set(http::field::allow, "GET, HEAD");
    response.set(http::field::content_type, "text/plain; charset=utf-8");
    response.body() = "405: this server only serves files (GET, HEAD), and WebSocket upgrades at /ws.\n";
    response.keep_alive(request.keep_alive());
    response.prepare_payload();
    return respond(std::move(response));
  }
  const std::optional<std::filesystem::path> file = files_.resolve(target);
  beast::error_code ec;
  http::file_body::value_type body;
  if (file) body.open(file->c_str(), beast::file_mode::scan, ec);
  if (!file || ec) return respond_text(http::status::not_found, files_.not_found_page(), request.keep_alive());
  const std::uint64_t size = body.size();
  if (request.method() == http::verb::head) {
    http::response<http::empty_body> response{http::status::ok, request.version()};
    response.set(http::field::content_type, std::string(content_type(*file)));
    response.content_length(size);
    response.keep_alive(request.keep_alive());
    return respond(std::move(response));
  }
  http::response<http::file_body> response{std::piecewise_construct, std::make_tuple(std::move(body)),
                                           std::make_tuple(http::status::ok, request.version())};
  response.set(http::field::content_type, std::string(content_type(*file)));
  response.set(http::field::cache_control, "no-cache");  // a rebuilt page is fetched again
  response.content_length(size);
  response.keep_alive(request.keep_alive());
  respond(std::move(response));
}

void WebSession::respond_text(http::status status, const std::string& body, bool keep_alive, const char* type) {
  http::response<http::string_body> response{status,
                                             parser_ && parser_->is_header_done() ? parser_->get().version() : 11};
  response.set(http::field::content_type, type);
  response.body() = body;
  response.keep_alive(keep_alive);
  response.prepare_payload();
  respond(std::move(response));
}

template <class Body>
void WebSession::respond(http::response<Body> response) {
  response.set(http::field::server, "fishtank-server");
  // Held by the handler: the response lives until it is written.
  auto held = std::make_shared<http::response<Body>>(std::move(response));
  http::async_write(http_, *held, [this, self = shared_from_this(), held](beast::error_code ec, std::size_t) {
    if (ec) return on_error(ec, "disconnected");
    if (held->need_eof()) return close("HTTP connection closed after the response");
    do_read_request();
  });
}

void WebSession::upgrade() {
  ws_.emplace(std::move(http_));
  ws_->set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
  websocket::permessage_deflate deflate;  // off: snapshots are coded compactly already, and it costs memory
  deflate.server_enable = false;
  deflate.client_enable = false;
  ws_->set_option(deflate);
  ws_->set_option(websocket::stream_base::decorator(
      [](websocket::response_type& response) { response.set(http::field::server, "fishtank-server"); }));
  ws_->binary(true);
  ws_->auto_fragment(false);
  ws_->read_message_max(max_body_bytes());
  ws_->async_accept(parser_->get(), [this, self = shared_from_this()](beast::error_code ec) {
    if (ec) return on_websocket_error(ec, "disconnected during the WebSocket handshake");
    upgraded_ = true;
    spdlog::info("client {} upgraded to a WebSocket", id());
    read_on();
    do_write();
  });
}

void WebSession::do_read() {
  buffer_.consume(buffer_.size());
  if (buffer_.capacity() > kKeptBufferBytes) buffer_.shrink_to_fit();
  ws_->read_message_max(max_body_bytes());
  ws_->async_read(buffer_, [this, self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec) return on_websocket_error(ec, "disconnected");
    received_bytes();
    if (ending()) return do_drain();
    if (!ws_->got_binary()) {
      stream_broken({protocol::DecodeStatus::malformed, nullptr,
                     "a text message; the protocol's frames travel as binary WebSocket messages"});
      return read_on();
    }
    const auto message = buffer_.cdata();
    message_received(static_cast<const std::uint8_t*>(message.data()), message.size());
    read_on();
  });
}

void WebSession::do_drain() {
  if (closed()) return;
  buffer_.consume(buffer_.size());
  ws_->async_read(buffer_, [this, self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec) return on_websocket_error(ec, "disconnected by the server");
    do_drain();
  });
}

void WebSession::write_frames(std::vector<asio::const_buffer> frames) {
  outgoing_ = std::move(frames);
  next_out_ = 0;
  out_bytes_ = 0;
  write_next_frame();
}

// One message per frame, the frame without its length prefix.
void WebSession::write_next_frame() {
  if (next_out_ == outgoing_.size()) return frames_written({}, out_bytes_);
  const asio::const_buffer frame = outgoing_[next_out_++] + protocol::kLengthPrefixBytes;
  ws_->async_write(frame, [this, self = shared_from_this()](beast::error_code ec, std::size_t n) {
    out_bytes_ += n;
    if (ec) return frames_written(ec, out_bytes_);
    write_next_frame();
  });
}

void WebSession::send_farewell() {
  // The close handshake done (the peer's close frame read, the TCP connection torn down), the session ends; the
  // read still pending then ends as aborted, which says nothing. A peer that never answers meets the grace period.
  const auto code = server_stopping() ? websocket::close_code::going_away : websocket::close_code::policy_error;
  ws_->async_close(code, [this, self = shared_from_this()](beast::error_code) { close("disconnected by the server"); });
}

void WebSession::close_transport() {
  beast::tcp_stream& stream = ws_ ? beast::get_lowest_layer(*ws_) : http_;
  boost::system::error_code ignored;
  stream.socket().shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
  stream.socket().close(ignored);
}

void WebSession::on_websocket_error(const boost::system::error_code& ec, const char* on_close) {
  if (ec == websocket::error::message_too_big)
    return close("sent a WebSocket message over " + std::to_string(max_body_bytes()) +
                 " bytes (closed with code 1009, message too big)");
  if (ec == websocket::error::closed) return close(on_close);
  on_error(ec, on_close);
}

}  // namespace fishtank::net
