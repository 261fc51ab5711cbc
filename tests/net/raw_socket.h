#pragma once
// A plain blocking socket to 127.0.0.1, for bytes no well-behaved client sends.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace fishtank::test {

class RawSocket {
 public:
  // receive_buffer > 0 shrinks the kernel's receive buffer before connecting.
  // Throws when the socket cannot be made or connected (and leaves no descriptor open).
  explicit RawSocket(std::uint16_t port, int receive_buffer = 0);
  ~RawSocket();
  RawSocket(const RawSocket&) = delete;
  RawSocket& operator=(const RawSocket&) = delete;

  void send(const std::vector<std::uint8_t>& bytes);
  void send_text(const std::string& text) { send(std::vector<std::uint8_t>(text.begin(), text.end())); }
  // Reads until what was read contains `text` (true) or `timeout` passes or the peer closes (false).
  bool read_until(const std::string& text, std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout);
  // Reads until the peer closes or `timeout` passes; true when it closed.
  bool read_until_closed(std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout);
  void close();

 private:
  int fd_ = -1;
};

}  // namespace fishtank::test
