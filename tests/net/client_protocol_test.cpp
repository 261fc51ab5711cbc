// The server's side of a conversation, without sockets: a peer's name reaches
// the log only as printable text, so it cannot forge a status line.

#include "server/net/client_protocol.h"

#include <catch2/catch.hpp>
#include <string>

using namespace fishtank;

TEST_CASE("a client name with a newline or an escape code is logged escaped and cut short", "[net]") {
  const net::ServerInfo info;
  net::ClientProtocol client(1, info);
  const std::string forged = "viewer\nt =    1.0 s  balls  9999\x1b[2K";
  const protocol::Frame hello = protocol::encode_hello(forged, false);
  client.on_frame(hello.data(), hello.size());
  const std::string& name = client.client_name();
  CHECK(name == "viewer\\x0at =    1.0 s  balls  9999\\x1b[2K");
  CHECK(name.find('\n') == std::string::npos);
  CHECK(name.find('\x1b') == std::string::npos);

  CHECK(net::printable_name(std::string(1000, 'a')) == std::string(net::kMaxNameBytes, 'a') + "...");
  CHECK(net::printable_name("back\\slash") == "back\\x5cslash");  // an escape cannot be faked either
  CHECK(net::printable_name("caf\xc3\xa9") == "caf\\xc3\\xa9");
}
