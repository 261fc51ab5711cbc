#pragma once
// Positions travel as 16 bits per axis over the tank bounds (Snapshot.positions):
// a 40-unit tank gives a step of 40 / 65535 = 0.00061 units, and the encoder's
// rounding error is at most half of that, plus float32's in the arithmetic. Shared by the server (quantize) and
// every client (dequantize).

#include <algorithm>
#include <cstdint>

#include "common/tank.h"

namespace fishtank::protocol {

inline constexpr float kQuantSteps = 65535.0f;

// Clamps v to [lo, hi] first, so a value outside the bounds lands on the nearest face.
inline std::uint16_t quantize(float v, float lo, float hi) {
  const float t = std::clamp((v - lo) / (hi - lo), 0.0f, 1.0f);  // NaN is not expected: the physics keeps balls finite
  return static_cast<std::uint16_t>(t * kQuantSteps + 0.5f);     // t >= 0, so truncation rounds to nearest
}

inline float dequantize(std::uint16_t q, float lo, float hi) {
  return lo + static_cast<float>(q) * ((hi - lo) / kQuantSteps);
}

// The largest error quantize() then dequantize() can introduce on an axis of that length.
inline float quantization_error(float lo, float hi) { return 0.5f * (hi - lo) / kQuantSteps; }

// One ball: three consecutive values of Snapshot.positions.
inline void quantize_position(Vec3 p, const TankBounds& tank, std::uint16_t out[3]) {
  out[0] = quantize(p.x, tank.min.x, tank.max.x);
  out[1] = quantize(p.y, tank.min.y, tank.max.y);
  out[2] = quantize(p.z, tank.min.z, tank.max.z);
}

inline Vec3 dequantize_position(const std::uint16_t q[3], const TankBounds& tank) {
  return {dequantize(q[0], tank.min.x, tank.max.x), dequantize(q[1], tank.min.y, tank.max.y),
          dequantize(q[2], tank.min.z, tank.max.z)};
}

}  // namespace fishtank::protocol
