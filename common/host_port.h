#pragma once
// The "host:port" a viewer or fishtank-client is told to connect to, checked before any attempt, so that a port
// that cannot exist is refused as a bad flag instead of retried forever ("[::1]:7878" for an IPv6 literal).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace fishtank {

struct HostPort {
  std::string host;
  std::uint16_t port = 0;
};

// A non-empty host, a colon, then a port 1 .. 65535 in decimal digits only; nullopt for anything else.
inline std::optional<HostPort> parse_host_port(std::string_view text) {
  const std::size_t colon = text.rfind(':');
  if (colon == std::string_view::npos) return std::nullopt;
  std::string_view host = text.substr(0, colon), digits = text.substr(colon + 1);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  if (host.empty() || digits.empty() || digits.size() > 5) return std::nullopt;
  unsigned port = 0;
  for (const char c : digits) {
    if (c < '0' || c > '9') return std::nullopt;
    port = port * 10 + static_cast<unsigned>(c - '0');
  }
  if (port < 1 || port > 65535) return std::nullopt;
  return HostPort{std::string(host), static_cast<std::uint16_t>(port)};
}

// host:port as --connect takes it back: an IPv6 address in brackets ("[::1]:7878").
inline std::string host_port_text(const std::string& host, const std::string& port) {
  return (host.find(':') == std::string::npos ? host : "[" + host + "]") + ":" + port;
}

}  // namespace fishtank
