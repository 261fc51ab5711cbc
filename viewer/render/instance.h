#pragma once
// One sphere to draw: what the interpolation writes and the instanced draw
// reads, 20 bytes per ball, uploaded as one buffer per frame.

#include <array>
#include <cstdint>

namespace fishtank::viewer {

struct SphereInstance {
  float x, y, z, radius;
  std::array<std::uint8_t, 4> rgba;  // normalised to [0, 1] by the vertex fetch
};
static_assert(sizeof(SphereInstance) == 20, "the vertex attribute layout assumes 20 bytes, no padding");

}  // namespace fishtank::viewer
