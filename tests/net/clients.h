#pragma once
// Client connections to a real server (ServerProcess) for the network tests:
// they share one io_context, pumped by the test thread, so a test reads their
// state between pumps without locks.

#include <boost/asio.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "client/connection.h"
#include "protocol/frame_codec.h"

namespace fishtank::test {

class Clients {
 public:
  explicit Clients(std::uint16_t port);
  ~Clients();

  std::shared_ptr<client::Connection> add(bool wants_player, std::uint32_t version = protocol::kProtocolVersion);
  // Added, welcomed and holding a first snapshot (REQUIREd, within 5 s).
  std::shared_ptr<client::Connection> add_watching(bool wants_player);
  void run_for(std::chrono::milliseconds d);
  // Pumps until done() or the timeout; returns done().
  bool wait_until(const std::function<bool()>& done,
                  std::chrono::milliseconds timeout = std::chrono::milliseconds(5000));
  bool all_welcomed() const;

 private:
  boost::asio::io_context io_;
  boost::asio::ip::tcp::endpoint server_;
  std::vector<std::shared_ptr<client::Connection>> all_;
};

// Whether c received an Error whose text starts with code ("too_slow: ...").
bool has_error(const client::Connection& c, const std::string& code);
// How many Errors of that code c received.
int errors_with(const client::Connection& c, const std::string& code);

// Every connection's snapshot count over `seconds` of pumping, as a rate.
std::vector<double> measure_rates(Clients& clients, const std::vector<std::shared_ptr<client::Connection>>& of,
                                  double seconds);

// `pings` Pings a quarter of a second apart from c, then a second for the last Pongs: the round trips, sorted.
std::vector<double> ping_round_trips(Clients& clients, client::Connection& c, int pings);
std::string round_trips_text(const std::vector<double>& rtt, int pings);

}  // namespace fishtank::test
