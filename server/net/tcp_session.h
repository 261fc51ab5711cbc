#pragma once
// A Session on a plain TCP socket: frames with their 4-byte length prefix.
//
//   reads:  [4-byte length] ─check cap─► [body, its buffer growing as bytes arrive]
//   writes: every waiting frame in one gathered async_write

#include <array>
#include <boost/asio.hpp>

#include "server/net/session.h"

namespace fishtank::net {

class TcpSession final : public Session {
 public:
  TcpSession(boost::asio::ip::tcp::socket socket, const boost::asio::ip::tcp::endpoint& peer, std::uint32_t id,
             const ServerInfo& info, SessionOwner& owner);

 private:
  void start_transport() override { do_read(); }
  void do_read() override;
  void do_drain() override;
  bool carries_frames() const override { return true; }
  void write_frames(std::vector<boost::asio::const_buffer> frames) override;
  void send_farewell() override;
  void close_transport() override;
  const char* transport_label() const override { return ""; }

  void do_read_body();
  // A browser given the TCP port: a plain HTTP answer naming the web viewer's port, then the end.
  void answer_browser();

  boost::asio::ip::tcp::socket socket_;
  std::array<std::uint8_t, protocol::kLengthPrefixBytes> header_{};
  protocol::Frame incoming_;     // the frame being received, grown as its bytes arrive
  std::size_t frame_bytes_ = 0;  // its full size, length prefix included
};

}  // namespace fishtank::net
