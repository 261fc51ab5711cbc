#pragma once
// The addresses other machines reach this one by, for a server bound to every address (0.0.0.0 or ::) to print
// instead of an address nobody can type: a room's laptops reach an IP address where no name server knows ours.

#include <boost/asio/ip/address.hpp>
#include <string>
#include <vector>

namespace fishtank::net {

// The up interfaces' addresses, loopback left out: IPv4, then IPv6 where with_v6 (link-local left out, as it
// needs an interface name to be reached).
std::vector<boost::asio::ip::address> machine_addresses(bool with_v6);

// An address as a URL or --connect writes it: an IPv6 one in brackets ([::1]:7878).
std::string url_host(const boost::asio::ip::address& address);

}  // namespace fishtank::net
