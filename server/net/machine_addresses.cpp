#include "server/net/machine_addresses.h"

#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>

namespace fishtank::net {

namespace ip = boost::asio::ip;

namespace {

// The address this machine sends from on its default route: a UDP socket's connect asks the routing table and
// sends nothing. Unspecified where there is no default route (a machine on no network, or IPv6 unrouted).
ip::address default_route_address(bool v6) {
  boost::asio::io_context io;
  ip::udp::socket probe(io);
  boost::system::error_code ec;
  // A public resolver's address: outside any network of this machine's, so the default route decides. (The
  // documentation ranges will not do: labs and virtual machines number their own networks from them.)
  probe.connect({ip::make_address(v6 ? "2001:4860:4860::8888" : "8.8.8.8"), 53}, ec);
  if (ec) return {};
  const ip::address local = probe.local_endpoint(ec).address();
  return ec ? ip::address() : local;
}

}  // namespace

std::vector<ip::address> put_first(std::vector<ip::address> addresses, const ip::address& first) {
  const auto found = std::find(addresses.begin(), addresses.end(), first);
  if (found != addresses.end()) std::rotate(addresses.begin(), found, found + 1);
  return addresses;
}

std::vector<ip::address> machine_addresses(bool with_v6) {
  std::vector<ip::address> v4, v6;
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return {};
  for (const ifaddrs* i = list; i; i = i->ifa_next) {
    if (!i->ifa_addr || !(i->ifa_flags & IFF_UP) || (i->ifa_flags & IFF_LOOPBACK)) continue;
    if (i->ifa_addr->sa_family == AF_INET) {
      const auto* in = reinterpret_cast<const sockaddr_in*>(i->ifa_addr);
      v4.push_back(ip::address_v4(ntohl(in->sin_addr.s_addr)));
    } else if (with_v6 && i->ifa_addr->sa_family == AF_INET6) {
      ip::address_v6::bytes_type bytes;
      std::copy_n(reinterpret_cast<const sockaddr_in6*>(i->ifa_addr)->sin6_addr.s6_addr, bytes.size(), bytes.begin());
      const ip::address_v6 address(bytes);
      if (!address.is_link_local()) v6.push_back(address);
    }
  }
  freeifaddrs(list);
  v4 = put_first(std::move(v4), default_route_address(false));
  if (with_v6) v6 = put_first(std::move(v6), default_route_address(true));
  v4.insert(v4.end(), v6.begin(), v6.end());
  return v4;
}

std::string url_host(const ip::address& address) {
  return address.is_v6() ? "[" + address.to_string() + "]" : address.to_string();
}

}  // namespace fishtank::net
