#pragma once
// Bytes on the wire as the network tests write and read them by hand.

#include <cstdint>
#include <string>
#include <vector>

#include "protocol/frame_codec.h"

namespace fishtank::test {

// A length prefix announcing `length` bytes, followed by `body_bytes` filler bytes.
protocol::Frame frame_with_length(std::uint32_t length, std::size_t body_bytes);

// An HTTP request that upgrades to a WebSocket at `path`.
std::string websocket_upgrade_request(const std::string& path = "/ws");

// The header of a masked (client-to-server) binary WebSocket frame announcing
// `length` payload bytes, then its 4-byte mask key.
std::vector<std::uint8_t> websocket_frame_header(std::uint64_t length);

// The code of every Error among the whole frames in what a client received, in order.
std::vector<std::string> error_codes(const std::vector<std::uint8_t>& bytes);

// The first of them (empty if none).
std::string first_error_code(const std::vector<std::uint8_t>& bytes);

}  // namespace fishtank::test
