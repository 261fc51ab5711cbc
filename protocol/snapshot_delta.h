#pragma once
// Positions of a snapshot coded against an earlier snapshot (the base) that the
// client acknowledged holding (Snapshot.unchanged and Snapshot.changes in
// protocol/fishtank.fbs). The quantised values are those of a full snapshot,
// bit for bit: only their coding differs.
//
//   balls 0 .. common-1   (common = min(base ball count, ball count))
//     unchanged  one bit per ball, least significant bit first: 1 = same three
//                values as in the base, nothing more is sent for it
//     changes    for each ball whose bit is 0, in id order, three exp-Golomb
//                codes (order 0) of the zigzagged difference to the base, x y z
//   balls common .. ball count-1   (new since the base)
//     changes    three raw 16-bit values each, after the differences
//
// A settled pile mostly sits still or jitters by a quantum, which the codes
// make 1 and 3 bits per axis; a ball that moved far costs at most 35 bits per
// axis. The bit stream is least-significant-bit first, padded with zeros to
// whole bytes.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fishtank::protocol {

// Bytes of Snapshot.unchanged for a base of base_count balls and a snapshot of count balls.
inline std::size_t unchanged_mask_bytes(std::uint32_t base_count, std::uint32_t count) {
  return (std::size_t{base_count < count ? base_count : count} + 7) / 8;
}

struct PositionsDelta {
  std::vector<std::uint8_t> unchanged;
  std::vector<std::uint8_t> changes;
};

// base holds 3 * base_count values, now 3 * count (quantised, id order). out is overwritten.
void encode_positions_delta(const std::uint16_t* base, std::uint32_t base_count, const std::uint16_t* now,
                            std::uint32_t count, PositionsDelta& out);

// Rebuilds the 3 * count values of a snapshot into out from its base and its
// two vectors. Returns why it cannot (a mask of the wrong length, a stream cut
// short or with bytes left over, a value outside 0 .. 65535), empty when done.
std::string decode_positions_delta(const std::uint16_t* base, std::uint32_t base_count, const std::uint8_t* unchanged,
                                   std::size_t unchanged_bytes, const std::uint8_t* changes, std::size_t changes_bytes,
                                   std::uint32_t count, std::uint16_t* out);

}  // namespace fishtank::protocol
