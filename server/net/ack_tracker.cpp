#include "server/net/ack_tracker.h"

#include <algorithm>

#include "protocol/received_snapshots.h"

namespace fishtank::net {

void AckTracker::sent(std::uint32_t tick) {
  sent_.push_back(tick);
  if (sent_.size() > protocol::kKeptBases) sent_.pop_front();
}

std::string AckTracker::acknowledged(std::uint32_t tick, bool want_keyframe) {
  if (want_keyframe) {
    base_.reset();
    return {};
  }
  if (sent_.empty() || tick > sent_.back()) {
    base_.reset();
    return "Ack for snapshot " + std::to_string(tick) + ", which has not been sent yet" +
           (sent_.empty() ? std::string() : " (newest sent: " + std::to_string(sent_.back()) + ")") +
           "; the next snapshot is a keyframe";
  }
  if (tick < sent_.front()) return {};  // too old to code against: harmless
  if (!std::binary_search(sent_.begin(), sent_.end(), tick)) {
    base_.reset();
    return "Ack for snapshot " + std::to_string(tick) +
           ", which was skipped for this client; the next snapshot is a keyframe";
  }
  if (!base_ || tick > *base_) base_ = tick;
  return {};
}

std::optional<std::uint32_t> AckTracker::prior() const {
  if (!base_) return std::nullopt;
  const auto at = std::lower_bound(sent_.begin(), sent_.end(), *base_);
  if (at == sent_.begin() || at == sent_.end() || *at != *base_) return std::nullopt;
  return *(at - 1);
}

}  // namespace fishtank::net
