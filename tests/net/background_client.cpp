#include "background_client.h"

#include <algorithm>

namespace fishtank::test {

namespace asio = boost::asio;

BackgroundClient::BackgroundClient(std::uint16_t port, bool wants_player, const std::string& name)
    : connection_(std::make_shared<client::Connection>(io_, name, wants_player)), publish_timer_(io_) {
  connection_->start(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  publish();
  thread_ = std::thread([this] { io_.run(); });
}

BackgroundClient::~BackgroundClient() {
  asio::post(io_, [this] {
    // cancel() misses a wait that has already expired: the flag stops that one.
    stopping_ = true;
    publish_timer_.cancel();
    connection_->close();
  });
  thread_.join();
}

void BackgroundClient::send(protocol::Frame frame) {
  asio::post(io_, [this, frame = std::move(frame)]() mutable { connection_->send(std::move(frame)); });
}

void BackgroundClient::publish() {
  {
    const client::ConnectionStats& stats = connection_->stats();
    std::lock_guard<std::mutex> lock(mutex_);
    published_.snapshots = stats.snapshots;
    published_.welcomed = connection_->welcomed();
    published_.closed = connection_->closed();
    published_.has_player = connection_->player_id().has_value();
    published_.ball_count = connection_->view().ball_count;
    published_.error_codes = stats.error_codes;
    published_.errors = stats.errors;
  }
  publish_timer_.expires_after(std::chrono::milliseconds(5));
  publish_timer_.async_wait([this](boost::system::error_code ec) {
    if (!ec && !stopping_) publish();
  });
}

ClientState BackgroundClient::state() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return published_;
}

bool BackgroundClient::has_error(const std::string& code) const {
  const ClientState s = state();
  return std::find(s.error_codes.begin(), s.error_codes.end(), code) != s.error_codes.end();
}

bool BackgroundClient::wait_until(const std::function<bool(const ClientState&)>& done,
                                  std::chrono::milliseconds timeout) const {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done(state()) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  return done(state());
}

double snapshot_rate(const BackgroundClient& client, const std::function<void()>& during) {
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t before = client.state().snapshots;
  during();
  // A second at least, with the attack still standing: over a tenth of one, a snapshot more or less
  // would move the rate by a sixth.
  std::this_thread::sleep_until(start + std::chrono::seconds(1));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return (client.state().snapshots - before) / seconds;
}

}  // namespace fishtank::test
