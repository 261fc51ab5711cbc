#pragma once
// Who may use the sandbox's controls (pause, step, reset, scene, time scale),
// which act on everyone's simulation: chosen with --control, stated to every
// client in its Welcome, enforced by the server for each command.

#include <optional>
#include <string>

namespace fishtank {

enum class ControlPolicy { players, everyone, nobody };

inline std::optional<ControlPolicy> parse_control_policy(const std::string& name) {
  if (name == "players") return ControlPolicy::players;
  if (name == "everyone") return ControlPolicy::everyone;
  if (name == "nobody") return ControlPolicy::nobody;
  return std::nullopt;
}

inline bool may_control(ControlPolicy policy, bool has_player) {
  return policy == ControlPolicy::everyone || (policy == ControlPolicy::players && has_player);
}

// One sentence for the HUD and for refusals.
inline std::string describe(ControlPolicy policy) {
  switch (policy) {
    case ControlPolicy::players:
      return "clients with a player sphere may pause, step, reset, change scene and time scale; observers may not";
    case ControlPolicy::everyone:
      return "every client may pause, step, reset, change scene and time scale";
    case ControlPolicy::nobody:
      return "nobody may pause, step, reset, change scene or time scale (server started with --control nobody)";
  }
  return {};
}

}  // namespace fishtank
