#include "wire_bytes.h"

namespace fishtank::test {

protocol::Frame frame_with_length(std::uint32_t length, std::size_t body_bytes) {
  protocol::Frame f(4 + body_bytes, 0xAB);
  for (int i = 0; i < 4; ++i) f[i] = static_cast<std::uint8_t>(length >> (8 * i));
  return f;
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
