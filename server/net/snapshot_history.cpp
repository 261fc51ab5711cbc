#include "server/net/snapshot_history.h"

#include <algorithm>
#include <chrono>

#include "protocol/received_snapshots.h"

namespace fishtank::net {

namespace {
std::size_t bytes_of(const PublishedSnapshot& s) { return s.quantised.size() * sizeof(std::uint16_t); }
}  // namespace

void SnapshotHistory::publish(SharedSnapshot snapshot) {
  kept_bytes_ += bytes_of(*snapshot);
  kept_.push_back(std::move(snapshot));
  while (kept_.size() > 1 && (kept_.size() > kKeptPublished || kept_bytes_ > kMaxBytes)) {
    kept_bytes_ -= bytes_of(*kept_.front());
    kept_.pop_front();
  }
  cache_.clear();
  stats_.snapshots.fetch_add(1, std::memory_order_relaxed);
}

const PublishedSnapshot* SnapshotHistory::find(std::uint32_t tick) const {
  for (const SharedSnapshot& s : kept_)
    if (s->header.tick == tick) return s.get();
  return nullptr;
}

CodedSnapshot SnapshotHistory::frame(const SharedSnapshot& snapshot, std::optional<std::uint32_t> base,
                                     std::optional<std::uint32_t> prior,
                                     const std::function<bool(std::uint32_t)>& keeps) {
  const PublishedSnapshot* base_snapshot = base && *base < snapshot->header.tick ? find(*base) : nullptr;
  const PublishedSnapshot* prior_snapshot = base_snapshot && prior && *prior < *base ? find(*prior) : nullptr;
  if (!base_snapshot) base.reset();  // a keyframe
  if (!prior_snapshot) prior.reset();
  const References references{base, prior};
  const bool newest = !kept_.empty() && kept_.back() == snapshot;
  if (newest) {
    for (const auto& [cached, coded] : cache_)
      if (cached == references) return coded;
    if (const CodedSnapshot* shared = shareable(base, keeps)) return *shared;
  }
  CodedSnapshot coded = code(*snapshot, base_snapshot, prior_snapshot);
  if (newest) cache_.emplace_back(references, coded);
  return coded;
}

const CodedSnapshot* SnapshotHistory::shareable(std::optional<std::uint32_t> base,
                                                const std::function<bool(std::uint32_t)>& keeps) const {
  if (!base || !keeps) return nullptr;
  const std::pair<References, CodedSnapshot>* newest = nullptr;
  for (const auto& entry : cache_) {
    const auto& [other_base, other_prior] = entry.first;
    if (!other_base || *other_base > *base || *base - *other_base > kShareLag) continue;
    if (!keeps(*other_base) || (other_prior && !keeps(*other_prior))) continue;
    if (!newest || *other_base > *newest->first.first) newest = &entry;
  }
  return newest ? &newest->second : nullptr;
}

CodedSnapshot SnapshotHistory::code(const PublishedSnapshot& s, const PublishedSnapshot* base,
                                    const PublishedSnapshot* prior) {
  const auto start = std::chrono::steady_clock::now();
  CodedSnapshot coded;
  protocol::DeltaReference ref;
  if (base) {
    ref.base = base->quantised.data();
    ref.base_count = base->ball_count;
    ref.base_tick = base->header.tick;
    if (prior) {
      ref.prior = prior->quantised.data();
      ref.prior_count = prior->ball_count;
      ref.prior_tick = prior->header.tick;
    }
    protocol::encode_positions_delta(ref, s.header.tick, s.quantised.data(), s.ball_count, delta_);
  }
  // Balls that all jumped far code longer than in full: then the full snapshot, so
  // no frame is ever larger than a keyframe (kMaxServerFrameBytes holds).
  coded.keyframe = !base || delta_.unchanged.size() + delta_.changes.size() >= s.quantised.size() * 2;
  if (coded.keyframe) {
    coded.frame = std::make_shared<const protocol::Frame>(
        protocol::encode_snapshot(s.header, s.quantised.data(), s.ball_count, s.player_ids.data(),
                                  s.player_positions.data(), s.player_ids.size()));
  } else {
    coded.frame = std::make_shared<const protocol::Frame>(protocol::encode_delta_snapshot(
        s.header, ref, delta_, s.ball_count, s.player_ids.data(), s.player_positions.data(), s.player_ids.size()));
  }
  const auto ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count();
  stats_.frames.fetch_add(1, std::memory_order_relaxed);
  stats_.keyframes.fetch_add(coded.keyframe, std::memory_order_relaxed);
  stats_.coding_ns.fetch_add(static_cast<std::uint64_t>(ns), std::memory_order_relaxed);
  stats_.frame_bytes.fetch_add(coded.frame->size(), std::memory_order_relaxed);
  return coded;
}

}  // namespace fishtank::net
