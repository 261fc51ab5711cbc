#pragma once
// A client connection on a thread of its own, so that it keeps reading at its
// own pace while the test thread plays a hostile peer with blocking sockets.
// The test thread reads a copy of its state, refreshed every few milliseconds.

#include <boost/asio.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "client/connection.h"

namespace fishtank::test {

struct ClientState {
  std::uint64_t snapshots = 0;
  bool welcomed = false;
  bool closed = false;
  bool has_player = false;
  std::uint32_t ball_count = 0;
  std::vector<std::string> error_codes;
  std::vector<std::string> errors;  // "code: message"
};

class BackgroundClient {
 public:
  BackgroundClient(std::uint16_t port, bool wants_player, const std::string& name);
  ~BackgroundClient();
  BackgroundClient(const BackgroundClient&) = delete;
  BackgroundClient& operator=(const BackgroundClient&) = delete;

  void send(protocol::Frame frame);
  ClientState state() const;
  bool has_error(const std::string& code) const;
  // Polls until done(state()) or the timeout; returns the last answer.
  bool wait_until(const std::function<bool(const ClientState&)>& done, std::chrono::milliseconds timeout) const;

 private:
  void publish();

  boost::asio::io_context io_;
  std::shared_ptr<client::Connection> connection_;
  boost::asio::steady_timer publish_timer_;
  bool stopping_ = false;  // its thread only
  mutable std::mutex mutex_;
  ClientState published_;
  std::thread thread_;
};

// Snapshots a client receives while `during` runs and for the rest of a second at least, per second.
double snapshot_rate(const BackgroundClient& client, const std::function<void()>& during);

}  // namespace fishtank::test
