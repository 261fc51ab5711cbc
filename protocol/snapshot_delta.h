#pragma once
// Positions of a snapshot coded against an earlier snapshot (the base) that the
// client acknowledged holding (Snapshot.unchanged and Snapshot.changes in
// protocol/fishtank.fbs). The quantised values are those of a full snapshot,
// bit for bit: only their coding differs.
//
//   balls 0 .. common-1   (common = min(base ball count, ball count))
//     unchanged  one bit per ball, least significant bit first: 1 = same three
//                values as in the base, nothing more is sent for it
//     changes    first the order k (3 bits) of the codes that follow, then for
//                each ball whose bit is 0, in id order, three exp-Golomb codes of
//                order k of the zigzagged difference to its prediction, x y z
//   balls common .. ball count-1   (new since the base)
//     changes    three raw 16-bit values each, after the differences
//
// The prediction is the base position, except for a ball that moved at least
// kMovingQuanta on an axis from the prior (the snapshot sent before the base,
// when the client holds it) to the base: it is predicted to go on at that
// velocity. So a settled pile, which sits still or jitters by a quantum, costs
// 1 bit per ball still and about 5 per ball jittering, and a falling or sliding
// ball the few bits of its change of velocity instead of its whole move. The
// encoder picks the order k that codes each snapshot in the fewest bits: 0 for a
// pile that jitters by a quantum, more while balls land and bounce by tens of
// quanta. The bit stream is least-significant-bit first, padded with zeros to
// whole bytes.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fishtank::protocol {

// Below this, a move from prior to base is taken for jitter, not velocity.
inline constexpr int kMovingQuanta = 4;

// Bytes of Snapshot.unchanged for a base of base_count balls and a snapshot of count balls.
inline std::size_t unchanged_mask_bytes(std::uint32_t base_count, std::uint32_t count) {
  return (std::size_t{base_count < count ? base_count : count} + 7) / 8;
}

// What a snapshot is coded against; positions are quantised, 3 per ball, in id order.
struct DeltaReference {
  const std::uint16_t* base = nullptr;
  std::uint32_t base_count = 0;
  std::uint32_t base_tick = 0;
  const std::uint16_t* prior = nullptr;  // null: no prediction from velocity
  std::uint32_t prior_count = 0;
  std::uint32_t prior_tick = 0;  // below base_tick
};

struct PositionsDelta {
  std::vector<std::uint8_t> unchanged;
  std::vector<std::uint8_t> changes;
  std::vector<std::uint32_t> residuals;  // the encoder's scratch, kept to reuse its memory
};

// now holds 3 * count values of snapshot `tick` (above ref.base_tick). out is overwritten.
void encode_positions_delta(const DeltaReference& ref, std::uint32_t tick, const std::uint16_t* now,
                            std::uint32_t count, PositionsDelta& out);

// Rebuilds the 3 * count values of snapshot `tick` into out from its reference
// and its two vectors. Returns why it cannot (a mask of the wrong length, a
// stream cut short or with bytes left over, a value outside 0 .. 65535), empty
// when done.
std::string decode_positions_delta(const DeltaReference& ref, std::uint32_t tick, const std::uint8_t* unchanged,
                                   std::size_t unchanged_bytes, const std::uint8_t* changes, std::size_t changes_bytes,
                                   std::uint32_t count, std::uint16_t* out);

}  // namespace fishtank::protocol
