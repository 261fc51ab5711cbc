#pragma once
// The scene presets' names (Reset.scene on the wire), in the order the
// viewer's number keys 1-4 choose them. The server defines what each one is
// (server/scenes/scene_presets.h); everyone else needs only the names.

#include <algorithm>
#include <array>
#include <string>

namespace fishtank {

inline constexpr std::array<const char*, 4> kSceneNames{"tank", "wide", "dam-break", "drop"};

inline bool is_scene_name(const std::string& name) {
  return std::any_of(kSceneNames.begin(), kSceneNames.end(), [&](const char* n) { return name == n; });
}

// "tank, wide, dam-break and drop", for messages.
inline std::string scene_names_text() {
  std::string text;
  for (std::size_t i = 0; i < kSceneNames.size(); ++i)
    text += (i == 0 ? "" : i + 1 == kSceneNames.size() ? " and " : ", ") + std::string(kSceneNames[i]);
  return text;
}

}  // namespace fishtank
