#pragma once
// The server's default --max-pending-per-address: connections from one address not yet past Hello. Beyond it a
// newcomer evicts the oldest as a stranger's stalled connection, so a client opening many (fishtank-client
// --clients) keeps no more than this many waiting for their Welcome at once.

#include <cstdint>

namespace fishtank {

inline constexpr std::uint32_t kDefaultMaxPendingPerAddress = 8;

}  // namespace fishtank
