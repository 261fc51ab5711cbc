#include "server/net/ack_tracker.h"

#include <algorithm>

#include "protocol/received_snapshots.h"

namespace fishtank::net {

void AckTracker::sent(std::uint32_t tick, Clock::time_point now, std::size_t bytes) {
  sent_.push_back(tick);
  if (sent_.size() > protocol::kKeptBases) sent_.pop_front();
  if (out_.empty()) {
    delivered_at_ = now;  // the link was idle: that time delivered nothing, and does not count
    alone_at_ = now;      // nothing of ours queued before it: its round trip is the path's own
    queued_since_alone_ = false;
  }
  out_.push_back({tick, now, bytes, delivered_, delivered_at_});
  if (out_.size() > kMaxOut) out_.pop_front();
}

std::string AckTracker::acknowledged(std::uint32_t tick, bool want_keyframe, Clock::time_point now) {
  // The snapshot came back, and every one sent before it arrived too.
  const auto later = std::find_if(out_.begin(), out_.end(), [&](const Out& o) { return o.tick > tick; });
  for (auto o = out_.begin(); o != later; ++o) delivered_ += o->bytes;
  if (later != out_.begin() && (later - 1)->tick == tick) {
    const Out& answered = *(later - 1);
    const Clock::duration took = now - answered.at;
    round_trips_.add(now, took);
    // The bytes answered since it went out, over the time they took: what the link carried meanwhile.
    // Over kRateInterval at least: a receiver may take in a short burst faster than its link carries.
    const double seconds =
        std::chrono::duration<double>(std::max<Clock::duration>(now - answered.delivered_at, kRateInterval)).count();
    const double rate = double(delivered_ - answered.delivered) / seconds;
    rates_.add(now, rate);
  }
  if (later != out_.begin()) delivered_at_ = now;
  out_.erase(out_.begin(), later);
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

std::optional<std::uint32_t> AckTracker::base() const {
  if (!base_ || sent_.empty() || *base_ < sent_.front()) return std::nullopt;
  return base_;
}

std::optional<std::uint32_t> AckTracker::prior() const {
  if (!base()) return std::nullopt;
  const auto at = std::lower_bound(sent_.begin(), sent_.end(), *base_);
  if (at == sent_.begin() || at == sent_.end() || *at != *base_) return std::nullopt;
  return *(at - 1);
}

bool AckTracker::keeps(std::uint32_t tick) const {
  const std::optional<std::uint32_t> held = base();
  return held && tick <= *held && std::binary_search(sent_.begin(), sent_.end(), tick);
}

std::optional<AckTracker::Clock::duration> AckTracker::quickest_round_trip() const { return round_trips_.best(); }

std::optional<AckTracker::Clock::time_point> AckTracker::oldest_unanswered() const {
  if (!acknowledges() || out_.empty()) return std::nullopt;
  return out_.front().at;
}

bool AckTracker::may_send(Clock::time_point now) {
  if (!acknowledges() || out_.empty()) return true;  // a client that never acknowledges is not held
  if (now - out_.back().at >= kLongestHold) return true;
  // Before its first round trip, one snapshot out: the first is a keyframe, the largest there is.
  if (!round_trips_.best()) return false;
  if (queued_since_alone_ && now - alone_at_ >= kProbeInterval) return false;  // draining: the next goes alone
  const Clock::duration quickest = *round_trips_.best();
  // Not more out than the link carries in a round trip (kRateInterval at least, as its rate) and the allowance.
  std::uint64_t out_bytes = 0;
  for (const Out& o : out_) out_bytes += o.bytes;
  const double span =
      std::chrono::duration<double>(std::max<Clock::duration>(quickest, kRateInterval) + kQueueAllowance).count();
  const bool carried =
      now - out_.front().at <= quickest + kQueueAllowance && double(out_bytes) <= delivery_rate() * span;
  queued_since_alone_ |= !carried;
  return carried;
}

}  // namespace fishtank::net
