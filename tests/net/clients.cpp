#include "clients.h"

#include <algorithm>
#include <catch2/catch.hpp>

namespace fishtank::test {

using Clock = std::chrono::steady_clock;

Clients::Clients(std::uint16_t port) : server_(boost::asio::ip::make_address("127.0.0.1"), port) {}

Clients::~Clients() {
  for (auto& c : all_) c->close();
  run_for(std::chrono::milliseconds(50));
}

std::shared_ptr<client::Connection> Clients::add(bool wants_player, std::uint32_t version) {
  auto c = std::make_shared<client::Connection>(io_, "test-" + std::to_string(all_.size() + 1), wants_player);
  c->start(server_, version);
  all_.push_back(c);
  return c;
}

std::shared_ptr<client::Connection> Clients::add_watching(bool wants_player) {
  auto c = add(wants_player);
  REQUIRE(wait_until([&] { return c->stats().snapshots > 0; }));
  return c;
}

void Clients::run_for(std::chrono::milliseconds d) {
  io_.restart();
  io_.run_for(d);
}

bool Clients::wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  while (!done() && Clock::now() < deadline) run_for(std::chrono::milliseconds(10));
  return done();
}

bool Clients::all_welcomed() const {
  return std::all_of(all_.begin(), all_.end(), [](auto& c) { return c->welcomed(); });
}

bool has_error(const client::Connection& c, const std::string& code) {
  return std::any_of(c.stats().errors.begin(), c.stats().errors.end(),
                     [&](const std::string& e) { return e.rfind(code, 0) == 0; });
}

int errors_with(const client::Connection& c, const std::string& code) {
  int n = 0;
  for (const std::string& e : c.stats().errors) n += e.rfind(code + ":", 0) == 0;
  return n;
}

std::vector<double> measure_rates(Clients& clients, const std::vector<std::shared_ptr<client::Connection>>& of,
                                  double seconds) {
  std::vector<std::uint64_t> before;
  for (auto& c : of) before.push_back(c->stats().snapshots);
  clients.run_for(std::chrono::milliseconds(static_cast<int>(seconds * 1000)));
  std::vector<double> rates;
  for (std::size_t i = 0; i < of.size(); ++i) rates.push_back((of[i]->stats().snapshots - before[i]) / seconds);
  return rates;
}

std::vector<double> ping_round_trips(Clients& clients, client::Connection& c, int pings) {
  for (int ping = 0; ping < pings; ++ping) {
    c.send_ping();
    clients.run_for(std::chrono::milliseconds(250));
  }
  clients.run_for(std::chrono::milliseconds(1000));
  std::vector<double> rtt = c.stats().rtt_ms;
  std::sort(rtt.begin(), rtt.end());
  return rtt;
}

std::string round_trips_text(const std::vector<double>& rtt, int pings) {
  return std::to_string(rtt.size()) + " of " + std::to_string(pings) + " Pings answered; round trips " +
         (rtt.empty() ? "none" : std::to_string(rtt.front()) + " .. " + std::to_string(rtt.back())) + " ms";
}

}  // namespace fishtank::test
