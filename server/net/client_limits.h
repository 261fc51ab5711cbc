#pragma once
// What one client may hold and do, so that strangers on a shared network cannot
// exhaust the server (flags in server/options.cpp, the manual's "Limits" table).
// Each limit, when it ends a connection or refuses a command, sends its own
// wire::ErrorCode.

#include <chrono>
#include <cstdint>

#include "common/pending_connections.h"
#include "server/control_policy.h"

namespace fishtank::net {

// Who may pour balls in (AddBalls): the same three choices as the controls.
using AddRights = ControlPolicy;

struct ClientLimits {
  // Beyond it a newcomer evicts the oldest connection that has not said Hello
  // (server_full); when every connection has, the newcomer gets server_full.
  std::uint32_t max_connections = 64;
  // Connections from one address that have not said Hello; a newcomer beyond it
  // evicts the oldest of them, so a stranger's stalled connections never exceed it.
  std::uint32_t max_pending_per_address = kDefaultMaxPendingPerAddress;
  double hello_timeout_s = 5.0;  // from connecting to a complete Hello; then hello_timeout
  // A write that cannot finish for this long: the peer does not read. It gets
  // idle_timeout when it sent nothing meanwhile either, too_slow when it did.
  double idle_timeout_s = 30.0;
  double player_idle_s = 120.0;               // no move for this long frees the sphere (player_idle); 0: never
  double max_commands_per_s = 200.0;          // messages a second, with as many in a burst; then command_flood
  AddRights add_rights = AddRights::players;  // others get not_permitted
  double add_balls_per_minute = 3000.0;       // per client, with as many in a burst; beyond it rate_limited
};

// A limit in seconds as a clock duration.
inline std::chrono::steady_clock::duration limit_duration(double seconds) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace fishtank::net
