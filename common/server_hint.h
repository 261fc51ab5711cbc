#pragma once
// What a client tells its user while nothing answers at the address it tried:
// the exact command that starts a server there. The viewer and fishtank-client
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

}  // namespace fishtank
