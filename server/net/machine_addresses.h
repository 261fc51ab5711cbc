#pragma once
// The addresses other machines reach this one by, for a server bound to every address (0.0.0.0 or ::) to print
// instead of an address nobody can type: a room's laptops reach an IP address where no name server knows ours.

#include <boost/asio/ip/address.hpp>
#include <string>
#include <vector>

namespace fishtank::net {

// The up interfaces' addresses, loopback left out: IPv4, then IPv6 where with_v6 (link-local left out, as it
// needs an interface name to be reached). The default route's own address comes first: a container bridge or a
// VPN's interface may be listed before the network a room shares.
std::vector<boost::asio::ip::address> machine_addresses(bool with_v6);

// `addresses` with `first` moved to the front where it is among them; otherwise unchanged.
std::vector<boost::asio::ip::address> put_first(std::vector<boost::asio::ip::address> addresses,
                                                const boost::asio::ip::address& first);

// An address as a URL or --connect writes it: an IPv6 one in brackets ([::1]:7878).
std::string url_host(const boost::asio::ip::address& address);

}  // namespace fishtank::net
