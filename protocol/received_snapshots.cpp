#include "protocol/received_snapshots.h"

#include "protocol/snapshot_delta.h"

namespace fishtank::protocol {

std::string ReceivedSnapshots::positions(const wire::Snapshot& s, std::vector<std::uint16_t>& out) {
  const std::uint32_t count = s.ball_count();
  if (!s.unchanged()) {
    out.assign(s.positions()->begin(), s.positions()->end());
  } else {
    const Kept* base = find(s.base_tick());
    const Kept* prior = s.predicted() ? find(s.prior_tick()) : nullptr;
    const std::string tick = "delta snapshot " + std::to_string(s.tick());
    if (!base || (s.predicted() && !prior))
      return tick + " is coded against snapshots " + std::to_string(s.base_tick()) +
             (s.predicted() ? " and " + std::to_string(s.prior_tick()) : std::string()) +
             ", which this client does not hold";
    if (!(s.tick() > s.base_tick() && (!prior || s.base_tick() > s.prior_tick())))
      return tick + " is not newer than its base, or its base not newer than its prior";
    DeltaReference ref;
    ref.base = base->positions.data();
    ref.base_count = static_cast<std::uint32_t>(base->positions.size() / 3);
    ref.base_tick = base->tick;
    if (ref.base_count != s.base_ball_count())
      return tick + " says its base has " + std::to_string(s.base_ball_count()) + " balls; it has " +
             std::to_string(ref.base_count);
    if (prior) {
      ref.prior = prior->positions.data();
      ref.prior_count = static_cast<std::uint32_t>(prior->positions.size() / 3);
      ref.prior_tick = prior->tick;
    }
    out.resize(3 * std::size_t{count});
    std::string why = decode_positions_delta(ref, s.tick(), s.unchanged()->data(), s.unchanged()->size(),
                                             s.changes()->data(), s.changes()->size(), count, out.data());
    if (!why.empty()) return tick + ": " + why;
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

const ReceivedSnapshots::Kept* ReceivedSnapshots::find(std::uint32_t tick) const {
  for (const Kept& k : kept_)
    if (k.tick == tick) return &k;
  return nullptr;
}

}  // namespace fishtank::protocol
