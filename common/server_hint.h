#pragma once
// What a client tells its user while nothing answers at the address it tried:
// the exact command that starts a server there, or, for a name that does not
// resolve, to check it. The viewer and fishtank-client
// say the same (the Python client says it in its own words).

#include <string>

namespace fishtank {

// "To start a server here: build/server/fishtank-server --port 7913"; for another host, with --bind.
inline std::string server_command_hint(const std::string& host, const std::string& port) {
  const std::string server = "build/server/fishtank-server";
  if (host == "127.0.0.1" || host == "localhost" || host == "::1")
    return "To start a server here: " + server + " --port " + port;
  return "To start a server on " + host + ": " + server + " --bind 0.0.0.0 --port " + port;
}

// What to do about error, a client's reason that no connection was made to host:port ("cannot resolve ..."
// from the name lookup, "cannot connect: ..." from the connect): check a name that does not resolve; for
// any other, start a server there.
inline std::string connection_advice(const std::string& host, const std::string& port, const std::string& error) {
  if (error.rfind("cannot resolve", 0) == 0) return "Check the host name, or give its IP address.";
  return server_command_hint(host, port);
}

}  // namespace fishtank
