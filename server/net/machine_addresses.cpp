#include "server/net/machine_addresses.h"

#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>

#include <algorithm>

namespace fishtank::net {

namespace ip = boost::asio::ip;

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
  v4.insert(v4.end(), v6.begin(), v6.end());
  return v4;
}

std::string url_host(const ip::address& address) {
  return address.is_v6() ? "[" + address.to_string() + "]" : address.to_string();
}

}  // namespace fishtank::net
