#pragma once
// What the sandbox's keys ask of the server (P, O, R, [ and ], 1-4), decided
// from the newest snapshot and kept apart from GLFW so it can be tested. The
// server decides whether this viewer may (Welcome.control_policy).

#include <optional>
#include <vector>

#include "protocol/frame_codec.h"
#include "viewer/net/snapshot.h"

namespace fishtank::viewer {

struct SandboxKeys {
  bool toggle_pause = false;  // P
  bool single_step = false;   // O: pauses first if running
  bool reset = false;         // R
  int time_scale_change = 0;  // ]: +1 faster, [: -1 slower
  std::optional<int> scene;   // 1-4: index into kSceneNames
};

// The steps of the time-scale ladder that [ and ] move along.
inline constexpr float kTimeScaleLadder[] = {0.1f, 0.25f, 0.5f, 1.0f};

// The next rung from `current` in `direction` (-1 slower, +1 faster), staying on the ladder's ends.
float next_time_scale(float current, int direction);

// The frames to send, in order; `newest` is null before the first snapshot (nothing is sent then).
std::vector<protocol::Frame> sandbox_frames(const SandboxKeys& keys, const Snapshot* newest);

}  // namespace fishtank::viewer
