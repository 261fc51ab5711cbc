#pragma once
// Which snapshot the next one sent to a client may be coded against: the
// newest one the client acknowledged (Ack) among those it was sent. Nothing
// acknowledged, an Ack with want_keyframe, or an Ack that cannot be true (a
// snapshot not sent yet, or one skipped for this client) all mean: send a
// keyframe. I/O free, owned by ClientProtocol.

#include <cstdint>
#include <deque>
#include <optional>
#include <string>

namespace fishtank::net {

class AckTracker {
 public:
  // A Snapshot with this tick went out to the client (ticks rise).
  void sent(std::uint32_t tick);
  // Returns why the Ack cannot be true, empty when it is taken (or merely old).
  std::string acknowledged(std::uint32_t tick, bool want_keyframe);
  // Empty: the next snapshot must be a keyframe.
  std::optional<std::uint32_t> base() const { return base_; }
  // The snapshot sent before base(), which the client holds too; empty when none is known.
  std::optional<std::uint32_t> prior() const;

 private:
  std::deque<std::uint32_t> sent_;  // the newest kKeptBases ticks sent, oldest first
  std::optional<std::uint32_t> base_;
};

}  // namespace fishtank::net
