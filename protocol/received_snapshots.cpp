#include "protocol/received_snapshots.h"

#include <algorithm>

#include "protocol/snapshot_delta.h"

namespace fishtank::protocol {

std::string ReceivedSnapshots::positions(const wire::Snapshot& s, std::vector<std::uint16_t>& out) {
  const std::uint32_t count = s.ball_count();
  if (!s.unchanged()) {
    out.assign(s.positions()->begin(), s.positions()->end());
  } else {
    const auto base = std::find_if(kept_.begin(), kept_.end(), [&](const Kept& k) { return k.tick == s.base_tick(); });
    if (base == kept_.end())
      return "delta snapshot " + std::to_string(s.tick()) + " is coded against snapshot " +
             std::to_string(s.base_tick()) + ", which this client does not hold";
    const std::uint32_t base_count = static_cast<std::uint32_t>(base->positions.size() / 3);
    if (base_count != s.base_ball_count())
      return "delta snapshot " + std::to_string(s.tick()) + " says its base has " +
             std::to_string(s.base_ball_count()) + " balls; it has " + std::to_string(base_count);
    out.resize(3 * std::size_t{count});
    std::string why =
        decode_positions_delta(base->positions.data(), base_count, s.unchanged()->data(), s.unchanged()->size(),
                               s.changes()->data(), s.changes()->size(), count, out.data());
    if (!why.empty()) return "delta snapshot " + std::to_string(s.tick()) + ": " + why;
  }
  // Reuses the oldest base's memory once the ring is full.
  Kept kept{s.tick(), {}};
  if (kept_.size() >= kKeptBases) {
    kept.positions = std::move(kept_.front().positions);
    kept_.pop_front();
  }
  kept.positions.assign(out.begin(), out.end());
  kept_.push_back(std::move(kept));
  return {};
}

}  // namespace fishtank::protocol
