#pragma once
// Command-line flags of fishtank-client.

#include <optional>
#include <string>

#include "client/script.h"

namespace fishtank::client {

struct ClientOptions {
  Script script;
  bool json = false;
};

struct ClientParse {
  std::optional<ClientOptions> options;  // empty: print message, exit with exit_code
  int exit_code = 0;
  std::string message;
};

ClientParse parse_client_options(int argc, const char* const argv[]);

}  // namespace fishtank::client
