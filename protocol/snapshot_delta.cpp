#include "protocol/snapshot_delta.h"

#include <algorithm>

namespace fishtank::protocol {

namespace {

// A difference of two 16-bit values zigzagged (0, -1, 1, -2, 2 ... -> 0, 1, 2, 3, 4 ...)
// is below 2^17, so its exp-Golomb code has at most 17 leading zeros.
constexpr int kMaxLeadingZeros = 17;
// The stream starts with the exp-Golomb order, in kOrderBits bits.
constexpr int kOrderBits = 3;
constexpr int kMaxGolombOrder = (1 << kOrderBits) - 1;

std::uint32_t zigzag(std::int32_t d) {
  return (static_cast<std::uint32_t>(d) << 1) ^ static_cast<std::uint32_t>(d >> 31);
}
std::int32_t unzigzag(std::uint32_t z) { return static_cast<std::int32_t>(z >> 1) ^ -static_cast<std::int32_t>(z & 1); }

int floor_log2(std::uint32_t v) { return 31 - __builtin_clz(v); }

class BitWriter {
 public:
  explicit BitWriter(std::vector<std::uint8_t>& out) : out_(out) {}

  // bits <= 32. Whole 32-bit words go out at once: byte by byte was the coder's main cost.
  void put(std::uint64_t value, int bits) {
    acc_ |= value << fill_;
    fill_ += bits;
    if (fill_ < 32) return;
    const std::uint8_t word[4] = {static_cast<std::uint8_t>(acc_), static_cast<std::uint8_t>(acc_ >> 8),
                                  static_cast<std::uint8_t>(acc_ >> 16), static_cast<std::uint8_t>(acc_ >> 24)};
    out_.insert(out_.end(), word, word + 4);
    acc_ >>= 32;
    fill_ -= 32;
  }
  // Order k: v >> k as below, then the k low bits of v.
  void exp_golomb(std::uint32_t v, int k) {
    exp_golomb(v >> k);
    if (k > 0) put(v & ((1u << k) - 1), k);
  }
  // n zeros, a one, then the n bits of v + 1 below its leading one.
  void exp_golomb(std::uint32_t v) {
    const std::uint32_t y = v + 1;
    const int n = floor_log2(y);
    const std::uint64_t low = y & ((1u << n) - 1);
    if (2 * n + 1 <= 32) return put(low << (n + 1) | 1u << n, 2 * n + 1);
    put(1u << n, n + 1);
    put(low, n);
  }
  void flush() {
    for (; fill_ > 0; fill_ -= 8, acc_ >>= 8) out_.push_back(static_cast<std::uint8_t>(acc_));
    acc_ = 0;
    fill_ = 0;
  }

 private:
  std::vector<std::uint8_t>& out_;
  std::uint64_t acc_ = 0;
  int fill_ = 0;
};

class BitReader {
 public:
  BitReader(const std::uint8_t* data, std::size_t bytes) : data_(data), bits_(8 * std::uint64_t{bytes}) {}

  // bits <= 32; false when the stream ends first.
  bool get(int bits, std::uint32_t& value) {
    if (pos_ + static_cast<std::uint64_t>(bits) > bits_) return false;
    value = peek(bits);
    pos_ += static_cast<std::uint64_t>(bits);
    return true;
  }
  bool exp_golomb(std::uint32_t& v, int k) {
    std::uint32_t high = 0, low = 0;
    if (!exp_golomb(high) || (k > 0 && !get(k, low))) return false;
    v = high << k | low;
    return true;
  }
  bool exp_golomb(std::uint32_t& v) {
    // The leading zeros counted in one look at the next bits, not one bit at a time.
    const int ahead = static_cast<int>(std::min<std::uint64_t>(kMaxLeadingZeros + 1, bits_ - pos_));
    const std::uint32_t window = peek(ahead);
    if (window == 0) return false;  // more zeros than any code has, or the stream ends among them
    const int n = __builtin_ctz(window);
    pos_ += static_cast<std::uint64_t>(n + 1);
    std::uint32_t low = 0;
    if (!get(n, low)) return false;
    v = ((1u << n) | low) - 1;
    return true;
  }
  // True when what is left is the zero padding of the last byte.
  bool only_padding_left() {
    std::uint32_t rest = 0;
    const int left = static_cast<int>(bits_ - pos_);
    return left < 8 && get(left, rest) && rest == 0;
  }

 private:
  // The next `bits` (<= 32, all within the stream) without moving past them.
  std::uint32_t peek(int bits) const {
    const std::size_t first = pos_ >> 3;
    const std::size_t last = (pos_ + bits + 7) >> 3;  // one past the last byte touched (at most 5 bytes)
    std::uint64_t word = 0;
    for (std::size_t b = first; b < last; ++b) word |= std::uint64_t{data_[b]} << (8 * (b - first));
    return static_cast<std::uint32_t>((word >> (pos_ & 7)) & ((std::uint64_t{1} << bits) - 1));
  }

  const std::uint8_t* data_;
  std::uint64_t bits_;
  std::uint64_t pos_ = 0;
};

// Where ball i is expected in snapshot `tick`: its base position, carried on at
// its velocity from prior to base when that was more than jitter.
void predict(const DeltaReference& ref, std::uint32_t tick, std::uint32_t i, std::int32_t out[3]) {
  const std::uint16_t* b = ref.base + 3 * std::size_t{i};
  for (int axis = 0; axis < 3; ++axis) out[axis] = b[axis];
  const std::int64_t ahead = std::int64_t{tick} - ref.base_tick, behind = std::int64_t{ref.base_tick} - ref.prior_tick;
  if (!ref.prior || i >= ref.prior_count || ahead <= 0 || behind <= 0) return;
  const std::uint16_t* a = ref.prior + 3 * std::size_t{i};
  std::int64_t moved[3];
  bool moving = false;
  for (int axis = 0; axis < 3; ++axis) {
    moved[axis] = std::int64_t{b[axis]} - a[axis];
    moving = moving || moved[axis] >= kMovingQuanta || moved[axis] <= -kMovingQuanta;
  }
  if (!moving) return;
  // Integer arithmetic, truncating, so that server and client predict the same value.
  for (int axis = 0; axis < 3; ++axis)
    out[axis] = static_cast<std::int32_t>(std::clamp<std::int64_t>(b[axis] + moved[axis] * ahead / behind, 0, 65535));
}

}  // namespace

void encode_positions_delta(const DeltaReference& ref, std::uint32_t tick, const std::uint16_t* now,
                            std::uint32_t count, PositionsDelta& out) {
  const std::uint32_t common = std::min(ref.base_count, count);
  out.unchanged.assign(unchanged_mask_bytes(ref.base_count, count), 0);
  out.changes.clear();
  out.residuals.clear();
  for (std::uint32_t i = 0; i < common; ++i) {
    const std::uint16_t* b = ref.base + 3 * std::size_t{i};
    const std::uint16_t* p = now + 3 * std::size_t{i};
    if (b[0] == p[0] && b[1] == p[1] && b[2] == p[2]) {
      out.unchanged[i >> 3] |= static_cast<std::uint8_t>(1u << (i & 7));
      continue;
    }
    std::int32_t expected[3];
    predict(ref, tick, i, expected);
    for (int axis = 0; axis < 3; ++axis) out.residuals.push_back(zigzag(std::int32_t{p[axis]} - expected[axis]));
  }
  // The order that codes this snapshot's differences in about the fewest bits, from
  // a histogram of their lengths: a code of order k for a value of L significant
  // bits takes about 2 max(L - k, 0) + 1 + k bits.
  std::uint64_t lengths[kMaxLeadingZeros + 1] = {};
  for (const std::uint32_t z : out.residuals) ++lengths[floor_log2(z + 1)];
  std::uint64_t best_bits = UINT64_MAX;
  int order = 0;
  for (int k = 0; k <= kMaxGolombOrder; ++k) {
    std::uint64_t bits = 0;
    for (int length = 0; length <= kMaxLeadingZeros; ++length)
      bits += lengths[length] * static_cast<std::uint64_t>(2 * std::max(length - k, 0) + 1 + k);
    if (bits < best_bits) {
      best_bits = bits;
      order = k;
    }
  }
  BitWriter changes(out.changes);
  changes.put(static_cast<std::uint32_t>(order), kOrderBits);
  for (const std::uint32_t z : out.residuals) changes.exp_golomb(z, order);
  for (std::size_t v = 3 * std::size_t{common}; v < 3 * std::size_t{count}; ++v) changes.put(now[v], 16);
  changes.flush();
}

std::string decode_positions_delta(const DeltaReference& ref, std::uint32_t tick, const std::uint8_t* unchanged,
                                   std::size_t unchanged_bytes, const std::uint8_t* changes, std::size_t changes_bytes,
                                   std::uint32_t count, std::uint16_t* out) {
  if (unchanged_bytes != unchanged_mask_bytes(ref.base_count, count))
    return "the unchanged mask has " + std::to_string(unchanged_bytes) + " bytes, " +
           std::to_string(unchanged_mask_bytes(ref.base_count, count)) + " expected";
  const std::uint32_t common = std::min(ref.base_count, count);
  BitReader reader(changes, changes_bytes);
  std::uint32_t order = 0;
  if (!reader.get(kOrderBits, order)) return "the changes stream is empty";
  for (std::uint32_t i = 0; i < common; ++i) {
    const std::uint16_t* b = ref.base + 3 * std::size_t{i};
    std::uint16_t* p = out + 3 * std::size_t{i};
    if (unchanged[i >> 3] >> (i & 7) & 1) {
      std::copy(b, b + 3, p);
      continue;
    }
    std::int32_t expected[3];
    predict(ref, tick, i, expected);
    for (int axis = 0; axis < 3; ++axis) {
      std::uint32_t z = 0;
      if (!reader.exp_golomb(z, static_cast<int>(order)))
        return "the changes stream ends inside ball " + std::to_string(i);
      const std::int32_t value = expected[axis] + unzigzag(z);
      if (value < 0 || value > 65535) return "ball " + std::to_string(i) + " moves outside the quantisation range";
      p[axis] = static_cast<std::uint16_t>(value);
    }
  }
  for (std::size_t v = 3 * std::size_t{common}; v < 3 * std::size_t{count}; ++v) {
    std::uint32_t raw = 0;
    if (!reader.get(16, raw)) return "the changes stream ends inside the new balls";
    out[v] = static_cast<std::uint16_t>(raw);
  }
  if (!reader.only_padding_left()) return "the changes stream has bytes after its last ball";
  return {};
}

}  // namespace fishtank::protocol
