#pragma once
// What a client tells its user while nothing answers at the address it tried:
// the exact command that starts a server there, or, for a name that does not
// resolve, to check it. The viewer and fishtank-client say the same (the
// Python client says it in its own words).

#include <string>
#include <string_view>

namespace fishtank {

// "To start a server here: build/server/fishtank-server --port 7913"; with --bind where the server's default
// address, 127.0.0.1, would not answer: the IPv6 loopback, another host (every address of its IP version).
inline std::string server_command_hint(const std::string& host, const std::string& port) {
  const std::string server = "build/server/fishtank-server";
  if (host == "127.0.0.1" || host == "localhost") return "To start a server here: " + server + " --port " + port;
  if (host == "::1") return "To start a server here: " + server + " --bind ::1 --port " + port;
  const char* every_address = host.find(':') == std::string::npos ? "0.0.0.0" : "::";
  return "To start a server on " + host + ": " + server + " --bind " + every_address + " --port " + port;
}

inline constexpr std::string_view kCannotResolve = "cannot resolve ";
inline constexpr std::string_view kClosedByServer = "the server closed the connection";

// A client's reason when the server closed the connection: with the last Error it sent ("code: message"), if any,
// which says why (a wrong port, a limit). connection_advice recognises both forms.
inline std::string closed_by_server_text(const std::string& last_error) {
  return std::string(kClosedByServer) + (last_error.empty() ? "" : " (" + last_error + ")");
}

// A client's reason that the name lookup of host failed, why: the one form connection_advice recognises.
inline std::string cannot_resolve_text(const std::string& host, const std::string& why) {
  return std::string(kCannotResolve) + host + ": " + why;
}

// What to do about error, a client's reason that no connection was made to host:port: check a name that
// does not resolve (cannot_resolve_text); for any other failure, start a server there.
inline std::string connection_advice(const std::string& host, const std::string& port, const std::string& error) {
  if (error.rfind(kCannotResolve, 0) == 0) return "Check the host name, or give its IP address.";
  // A server answered and said why it closed: starting another there is not the remedy.
  if (error.rfind(std::string(kClosedByServer) + " (", 0) == 0) return "";
  return server_command_hint(host, port);
}

}  // namespace fishtank
