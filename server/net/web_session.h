#pragma once
// A Session that comes over HTTP (Boost.Beast): static files from the web root
// until the client upgrades at /ws; from then on the same conversation as
// TcpSession, one frame per binary WebSocket message without its length prefix.
//
//   HTTP:  request (header <= kMaxHeaderBytes: else 431; body <= kMaxRequestBodyBytes: else 413)
//            GET/HEAD a file of the root ──► 200, or 404; another method ──► 405
//            Upgrade at /ws ──► WebSocket; an upgrade anywhere else ──► 404
//   WebSocket: a read always pending (read_message_max: 1 KiB before Hello,
//            kMaxClientFrameBytes after; beyond it Beast closes with code 1009);
//            writes one message at a time, a frame each, the Session's one write in flight.
// Until Hello, the connection counts as one that has not said Hello (NetServer
// may evict it) and --hello-timeout applies, whether it fetches files or not.

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <optional>
#include <vector>

#include "server/net/session.h"
#include "server/net/static_files.h"

namespace fishtank::net {

class WebSession final : public Session {
 public:
  static constexpr std::uint32_t kMaxHeaderBytes = 8 * 1024;
  // GET and HEAD carry no body; a small one is read so that its request gets its 405.
  static constexpr std::uint64_t kMaxRequestBodyBytes = 1024;

  WebSession(boost::asio::ip::tcp::socket socket, const boost::asio::ip::tcp::endpoint& peer, std::uint32_t id,
             const ServerInfo& info, SessionOwner& owner, const StaticFiles& files);

 private:
  using Request = boost::beast::http::request<boost::beast::http::string_body>;

  // HTTP, before the upgrade.
  void start_transport() override { do_read_request(); }
  void do_read_request();
  void on_request();
  void upgrade();
  // A fishtank-viewer or client given the web port: an Error frame naming the TCP port, then the end.
  bool reads_as_fishtank_frame() const;
  void answer_fishtank_client();
  void drain_before_upgrade();
  void respond_text(boost::beast::http::status status, const std::string& body, bool keep_alive,
                    const char* type = "text/html; charset=utf-8");
  template <class Body>
  void respond(boost::beast::http::response<Body> response);

  // WebSocket, after it.
  void do_read() override;
  void do_drain() override;
  bool carries_frames() const override { return upgraded_; }
  void write_frames(std::vector<boost::asio::const_buffer> frames) override;
  void write_next_frame();
  void send_farewell() override;
  void close_transport() override;
  const char* transport_label() const override { return " (web)"; }
  void on_websocket_error(const boost::system::error_code& ec, const char* on_close);

  const StaticFiles& files_;
  boost::beast::tcp_stream http_;  // moved into ws_ at the upgrade
  std::optional<boost::beast::websocket::stream<boost::beast::tcp_stream>> ws_;
  bool upgraded_ = false;
  boost::beast::flat_buffer buffer_;  // HTTP's, then each WebSocket message
  std::optional<boost::beast::http::request_parser<boost::beast::http::string_body>> parser_;

  std::vector<boost::asio::const_buffer> outgoing_;  // the frames of the write in flight
  std::size_t next_out_ = 0;
  std::size_t out_bytes_ = 0;
};

}  // namespace fishtank::net
