// fishtank-client against a server that is not ours: whatever text it sends (an Error's message, a scene's
// name) reaches the summary as printable ASCII, so it cannot forge the client's lines and the JSON summary
// can be written (nlohmann::json throws on invalid UTF-8).

#include <boost/asio.hpp>
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "client/script.h"
#include "protocol/frame_codec.h"

using namespace fishtank;
namespace asio = boost::asio;

namespace {

bool printable_ascii(const std::string& text) {
  for (const char c : text)
    if (c < 0x20 || c > 0x7e) return false;
  return true;
}

}  // namespace

TEST_CASE("a foreign server's escape codes and invalid UTF-8 reach the client's summary as printable text",
          "[net][client]") {
  const std::string hostile = "ok\n\x1b[2Kforged line \xff\xfe \xc3";
  asio::io_context io;
  asio::ip::tcp::acceptor acceptor(io, {asio::ip::make_address("127.0.0.1"), 0});
  std::thread server([&] {
    asio::ip::tcp::socket peer(io);
    acceptor.accept(peer);
    protocol::WelcomeInfo welcome;
    welcome.server_variant = welcome.simd_level = "foreign";
    welcome.dt = 1e-3f;
    protocol::SnapshotHeader header;
    header.scene = hostile;
    const std::uint16_t position[3] = {0, 0, 0};
    const std::uint8_t kind = 0;
    for (const protocol::Frame& f : {protocol::encode_welcome(welcome), protocol::encode_ball_kinds(0, &kind, 1),
                                     protocol::encode_snapshot(header, position, 1, nullptr, nullptr, 0),
                                     protocol::encode_error(wire::ErrorCode::invalid_value, hostile)})
      asio::write(peer, asio::buffer(f));
    boost::system::error_code ec;  // read until the client leaves
    char sink[4096];
    while (!ec) peer.read_some(asio::buffer(sink), ec);
  });

  client::Script script;
  script.port = acceptor.local_endpoint().port();
  script.observer = true;
  script.duration = 0.5;
  const client::Summary s = client::run_script(script);
  server.join();

  REQUIRE(s.welcomed == 1);
  CHECK(s.scene == "ok\\x0a\\x1b[2Kforged line \\xff\\xfe \\xc3");
  REQUIRE(s.error_messages.size() == 1);
  CHECK(s.error_messages[0] == "invalid_value: " + s.scene);
  CHECK(printable_ascii(s.scene));
  CHECK_NOTHROW(nlohmann::json{{"scene", s.scene}, {"error_messages", s.error_messages}}.dump());
}
