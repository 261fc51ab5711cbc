#pragma once
// The scene's fixed facts (SPEC 1): the tank, the three ball kinds, the player.

#include <array>
#include <cstdint>

#include "common/vec3.h"

namespace fishtank {

// Axis-aligned box; the default is the 40-unit fish tank, y up.
struct TankBounds {
  Vec3 min{-20.0f, 0.0f, -20.0f};
  Vec3 max{20.0f, 40.0f, 20.0f};

  Vec3 size() const { return max - min; }
  float volume() const {
    Vec3 s = size();
    return s.x * s.y * s.z;
  }
};

struct BallKind {
  float diameter;
  float mass;
  std::array<std::uint8_t, 3> rgb;
};

// Mass grows with diameter, not volume (SPEC 1.3).
inline constexpr std::array<BallKind, 3> kBallKinds{{
    {1.0f, 1.0f, {230, 40, 40}},
    {2.0f, 2.0f, {40, 200, 60}},
    {3.0f, 3.0f, {50, 90, 230}},
}};
inline constexpr int kKindCount = static_cast<int>(kBallKinds.size());
inline constexpr float kMinBallDiameter = 1.0f;
inline constexpr float kMaxBallDiameter = 3.0f;
inline constexpr float kPlayerDiameter = 1.0f;

// Mean volume of one ball of the equal-numbers mix, for capacity estimates.
inline constexpr float mean_ball_volume() {
  float sum = 0.0f;
  for (const BallKind& k : kBallKinds) sum += 3.14159265f / 6.0f * k.diameter * k.diameter * k.diameter;
  return sum / kKindCount;
}

}  // namespace fishtank
