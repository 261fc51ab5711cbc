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
// The longest code of a residual: 17 leading zeros, a one, 17 bits, the order's 7.
constexpr int kMaxCodeBits = 2 * kMaxLeadingZeros + 1 + kMaxGolombOrder;
static_assert(kMaxCodeBits <= 56, "a code is put and read in one 64-bit word");

std::uint32_t zigzag(std::int32_t d) {
  return (static_cast<std::uint32_t>(d) << 1) ^ static_cast<std::uint32_t>(d >> 31);
}
std::int32_t unzigzag(std::uint32_t z) { return static_cast<std::int32_t>(z >> 1) ^ -static_cast<std::int32_t>(z & 1); }

int floor_log2(std::uint32_t v) { return 31 - __builtin_clz(v); }

// Writes each code whole, as one 8-byte store into a vector sized beforehand
// for the stream expected (grown only should that be short): growing the
// vector word by word was the coder's main cost.
class BitWriter {
 public:
  BitWriter(std::vector<std::uint8_t>& out, std::size_t expected_bytes) : out_(out) { out_.resize(expected_bytes + 8); }

  // bits <= 56: with at most 7 bits pending, the 64-bit accumulator holds them all.
  void put(std::uint64_t value, int bits) {
    if (size_ + 8 > out_.size()) out_.resize(2 * out_.size());
    acc_ |= value << fill_;
    fill_ += bits;
    std::uint8_t* at = out_.data() + size_;
    for (int b = 0; b < 8; ++b) at[b] = static_cast<std::uint8_t>(acc_ >> (8 * b));  // one store on x86
    size_ += static_cast<std::size_t>(fill_ >> 3);
    acc_ >>= fill_ & ~7;
    fill_ &= 7;
  }
  // Order k, in one code of at most kMaxCodeBits: n zeros, a one, the n bits of
  // y = (v >> k) + 1 below its leading one, then the k low bits of v.
  void exp_golomb(std::uint32_t v, int k) {
    const std::uint64_t y = (v >> k) + 1;
    const int n = floor_log2(static_cast<std::uint32_t>(y));
    const std::uint64_t low_k = v & ((1u << k) - 1);
    const std::uint64_t low = y ^ (std::uint64_t{1} << n);
    put((low << 1 | 1) << n | low_k << (2 * n + 1), 2 * n + 1 + k);
  }
  // Pads the last byte with zeros and trims the vector to the stream.
  void flush() {
    if (fill_ > 0) out_[size_++] = static_cast<std::uint8_t>(acc_);
    out_.resize(size_);
  }

 private:
  std::vector<std::uint8_t>& out_;
  std::size_t size_ = 0;
  std::uint64_t acc_ = 0;
  int fill_ = 0;
};

class BitReader {
 public:
  BitReader(const std::uint8_t* data, std::size_t bytes) : data_(data), bytes_(bytes) {}

  // bits <= 32; false when the stream ends first.
  bool get(int bits, std::uint32_t& value) {
    if (pos_ + static_cast<std::uint64_t>(bits) > stream_bits()) return false;
    value = static_cast<std::uint32_t>(peek() & ((std::uint64_t{1} << bits) - 1));
    pos_ += static_cast<std::uint64_t>(bits);
    return true;
  }
  // Order k, read in one look at the next bits (the code is at most kMaxCodeBits long).
  bool exp_golomb(std::uint32_t& v, int k) {
    const std::uint64_t next = peek();
    const std::uint64_t zeros_window = next & ((std::uint64_t{1} << (kMaxLeadingZeros + 1)) - 1);
    if (zeros_window == 0) return false;  // more zeros than any code has, or the stream ends among them
    const int n = __builtin_ctzll(zeros_window);
    const int bits = 2 * n + 1 + k;
    if (pos_ + static_cast<std::uint64_t>(bits) > stream_bits()) return false;
    const std::uint64_t low = (next >> (n + 1)) & ((std::uint64_t{1} << n) - 1);
    const std::uint64_t low_k = (next >> (2 * n + 1)) & ((std::uint64_t{1} << k) - 1);
    v = static_cast<std::uint32_t>(((std::uint64_t{1} << n | low) - 1) << k | low_k);
    pos_ += static_cast<std::uint64_t>(bits);
    return true;
  }
  // True when what is left is the zero padding of the last byte.
  bool only_padding_left() {
    std::uint32_t rest = 0;
    const int left = static_cast<int>(stream_bits() - pos_);
    return left < 8 && get(left, rest) && rest == 0;
  }

 private:
  // The next 57 bits or more, zeros past the stream's end: one 8-byte read where
  // the stream has 8 bytes left.
  std::uint64_t peek() const {
    const std::size_t first = pos_ >> 3;
    std::uint64_t word = 0;
    if (first + 8 <= bytes_) {
      for (int b = 0; b < 8; ++b) word |= std::uint64_t{data_[first + b]} << (8 * b);  // one load on x86
    } else {
      for (std::size_t b = first; b < bytes_; ++b) word |= std::uint64_t{data_[b]} << (8 * (b - first));
    }
    return word >> (pos_ & 7);
  }

  std::uint64_t stream_bits() const { return 8 * std::uint64_t{bytes_}; }

  const std::uint8_t* data_;
  std::size_t bytes_;
  std::uint64_t pos_ = 0;
};

// Where each ball is expected in snapshot `tick`: its base position, carried on
// at its velocity from prior to base when that was more than jitter.
class Predictor {
 public:
  Predictor(const DeltaReference& ref, std::uint32_t tick)
      : ref_(ref),
        ahead_(std::int64_t{tick} - ref.base_tick),
        behind_(std::int64_t{ref.base_tick} - ref.prior_tick),
        carries_(ref.prior && ahead_ > 0 && behind_ > 0) {}

  void operator()(std::uint32_t i, std::int32_t out[3]) const {
    const std::uint16_t* b = ref_.base + 3 * std::size_t{i};
    for (int axis = 0; axis < 3; ++axis) out[axis] = b[axis];
    if (!carries_ || i >= ref_.prior_count) return;
    const std::uint16_t* a = ref_.prior + 3 * std::size_t{i};
    std::int64_t moved[3];
    bool moving = false;
    for (int axis = 0; axis < 3; ++axis) {
      moved[axis] = std::int64_t{b[axis]} - a[axis];
      moving = moving || moved[axis] >= kMovingQuanta || moved[axis] <= -kMovingQuanta;
    }
    if (!moving) return;
    // Integer arithmetic, truncating, so that server and client predict the same
    // value; snapshots a tick apart (the usual case) need no divide.
    for (int axis = 0; axis < 3; ++axis) {
      const std::int64_t carried = behind_ == 1 ? moved[axis] * ahead_ : moved[axis] * ahead_ / behind_;
      out[axis] = static_cast<std::int32_t>(std::clamp<std::int64_t>(b[axis] + carried, 0, 65535));
    }
  }

 private:
  const DeltaReference& ref_;
  const std::int64_t ahead_, behind_;
  const bool carries_;
};

}  // namespace

void encode_positions_delta(const DeltaReference& ref, std::uint32_t tick, const std::uint16_t* now,
                            std::uint32_t count, PositionsDelta& out) {
  const std::uint32_t common = std::min(ref.base_count, count);
  out.unchanged.assign(unchanged_mask_bytes(ref.base_count, count), 0);
  // Never shrunk, so that reusing `out` writes without clearing.
  if (out.residuals.size() < 3 * std::size_t{common}) out.residuals.resize(3 * std::size_t{common});
  std::uint32_t* residual = out.residuals.data();
  // Histograms of the residuals' lengths, for the order below: one per axis, so
  // that equal lengths in a row do not wait on each other's increment.
  std::uint64_t lengths[3][kMaxLeadingZeros + 1] = {};
  const Predictor predict(ref, tick);
  for (std::uint32_t i = 0; i < common; ++i) {
    const std::uint16_t* b = ref.base + 3 * std::size_t{i};
    const std::uint16_t* p = now + 3 * std::size_t{i};
    if (b[0] == p[0] && b[1] == p[1] && b[2] == p[2]) {
      out.unchanged[i >> 3] |= static_cast<std::uint8_t>(1u << (i & 7));
      continue;
    }
    std::int32_t expected[3];
    predict(i, expected);
    for (int axis = 0; axis < 3; ++axis) {
      const std::uint32_t z = zigzag(std::int32_t{p[axis]} - expected[axis]);
      *residual++ = z;
      ++lengths[axis][floor_log2(z + 1)];
    }
  }
  const std::uint32_t* const residuals_end = residual;
  // The order that codes this snapshot's differences in about the fewest bits: a
  // code of order k for a value of L significant bits takes about 2 max(L - k, 0) + 1 + k bits.
  std::uint64_t best_bits = UINT64_MAX;
  int order = 0;
  for (int k = 0; k <= kMaxGolombOrder; ++k) {
    std::uint64_t bits = 0;
    for (int length = 0; length <= kMaxLeadingZeros; ++length)
      bits += (lengths[0][length] + lengths[1][length] + lengths[2][length]) *
              static_cast<std::uint64_t>(2 * std::max(length - k, 0) + 1 + k);
    if (bits < best_bits) {
      best_bits = bits;
      order = k;
    }
  }
  const std::size_t residual_count = static_cast<std::size_t>(residuals_end - out.residuals.data());
  const std::size_t new_values = 3 * (std::size_t{count} - common);
  // A code is at most 2 bits longer than the estimate above.
  BitWriter changes(out.changes, (kOrderBits + best_bits + 2 * residual_count + 16 * new_values) / 8);
  changes.put(static_cast<std::uint32_t>(order), kOrderBits);
  for (const std::uint32_t* z = out.residuals.data(); z != residuals_end; ++z) changes.exp_golomb(*z, order);
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
  const Predictor predict(ref, tick);
  for (std::uint32_t i = 0; i < common; ++i) {
    const std::uint16_t* b = ref.base + 3 * std::size_t{i};
    std::uint16_t* p = out + 3 * std::size_t{i};
    if (unchanged[i >> 3] >> (i & 7) & 1) {
      std::copy(b, b + 3, p);
      continue;
    }
    std::int32_t expected[3];
    predict(i, expected);
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
