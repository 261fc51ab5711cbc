// The address a server bound to every address gives a room: the default route's before a container bridge's.

#include "server/net/machine_addresses.h"

#include <catch2/catch.hpp>

using namespace fishtank::net;
namespace ip = boost::asio::ip;

TEST_CASE("the default route's address is put before a bridge listed ahead of it, and the rest keep their order",
          "[net]") {
  const ip::address bridge = ip::make_address("172.17.0.1"), lan = ip::make_address("192.168.1.5"),
                    vpn = ip::make_address("10.8.0.2");
  CHECK(put_first({bridge, vpn, lan}, lan) == std::vector<ip::address>{lan, bridge, vpn});
  CHECK(put_first({lan, bridge}, lan) == std::vector<ip::address>{lan, bridge});
  // No default route (the probe's address is unspecified), or one not among the addresses: the order stays.
  CHECK(put_first({bridge, lan}, ip::address()) == std::vector<ip::address>{bridge, lan});
  CHECK(put_first({}, lan).empty());
}

TEST_CASE("this machine's addresses leave out loopback and IPv6 link-local, and list IPv4 first", "[net]") {
  const auto addresses = machine_addresses(true);
  bool seen_v6 = false;
  for (const ip::address& a : addresses) {
    INFO(a.to_string());
    CHECK_FALSE(a.is_loopback());
    CHECK_FALSE(a.is_unspecified());
    if (a.is_v6()) CHECK_FALSE(a.to_v6().is_link_local());
    CHECK_FALSE((seen_v6 && a.is_v4()));
    seen_v6 |= a.is_v6();
  }
}
