#pragma once
// The scene presets' names (Reset.scene on the wire), in the order the
// viewer's number keys 1-4 choose them. The server defines what each one is
// (server/scenes/scene_presets.h); clients only need the names.

#include <array>

namespace fishtank {

inline constexpr std::array<const char*, 4> kSceneNames{"tank", "wide", "dam-break", "drop"};

}  // namespace fishtank
