#include "wire_bytes.h"

namespace fishtank::test {

protocol::Frame frame_with_length(std::uint32_t length, std::size_t body_bytes) {
  protocol::Frame f(4 + body_bytes, 0xAB);
  for (int i = 0; i < 4; ++i) f[i] = static_cast<std::uint8_t>(length >> (8 * i));
  return f;
}

std::string websocket_upgrade_request(const std::string& path) {
  return "GET " + path +
         " HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
         "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
}

std::vector<std::uint8_t> websocket_frame_header(std::uint64_t length) {
  std::vector<std::uint8_t> header{0x82};  // FIN, binary
  if (length < 126) {
    header.push_back(static_cast<std::uint8_t>(0x80 | length));
  } else if (length <= 0xFFFF) {
    header.insert(header.end(),
                  {0x80 | 126, static_cast<std::uint8_t>(length >> 8), static_cast<std::uint8_t>(length)});
  } else {
    header.push_back(0x80 | 127);
    for (int shift = 56; shift >= 0; shift -= 8) header.push_back(static_cast<std::uint8_t>(length >> shift));
  }
  header.insert(header.end(), {0x12, 0x34, 0x56, 0x78});  // the mask key
  return header;
}

std::vector<std::string> error_codes(const std::vector<std::uint8_t>& bytes) {
  std::vector<std::string> codes;
  protocol::FrameReader reader(protocol::Direction::to_client);
  reader.append(bytes.data(), bytes.size());
  while (auto r = reader.next()) {
    if (!r->ok()) break;
    if (r->message->payload_type() == wire::Payload::Error)
      codes.emplace_back(wire::EnumNameErrorCode(r->message->payload_as_Error()->code()));
  }
  return codes;
}

std::string first_error_code(const std::vector<std::uint8_t>& bytes) {
  const std::vector<std::string> codes = error_codes(bytes);
  return codes.empty() ? std::string() : codes.front();
}

}  // namespace fishtank::test
