#include "viewer/sandbox_controls.h"

#include "common/scene_names.h"

namespace fishtank::viewer {

float next_time_scale(float current, int direction) {
  constexpr int kRungs = sizeof kTimeScaleLadder / sizeof kTimeScaleLadder[0];
  if (direction > 0) {
    for (float rung : kTimeScaleLadder)
      if (rung > current * 1.001f) return rung;
    return kTimeScaleLadder[kRungs - 1];
  }
  for (int i = kRungs - 1; i >= 0; --i)
    if (kTimeScaleLadder[i] < current * 0.999f) return kTimeScaleLadder[i];
  return kTimeScaleLadder[0];
}

std::vector<protocol::Frame> sandbox_frames(const SandboxKeys& keys, const Snapshot* newest) {
  std::vector<protocol::Frame> frames;
  if (!newest) return frames;
  if (keys.scene && *keys.scene >= 0 && *keys.scene < static_cast<int>(kSceneNames.size()))
    frames.push_back(
        protocol::encode_reset(kSceneNames[static_cast<std::size_t>(*keys.scene)], std::nullopt));
  if (keys.reset) frames.push_back(protocol::encode_reset("", std::nullopt));
  if (keys.time_scale_change != 0) {
    // A server that does not say (0) runs at real time.
    const float current = newest->time_scale_set > 0.0f ? newest->time_scale_set : 1.0f;
    frames.push_back(protocol::encode_set_time_scale(next_time_scale(current, keys.time_scale_change)));
  }
  if (keys.toggle_pause) frames.push_back(protocol::encode_pause(!newest->paused));
  if (keys.single_step) {
    if (!newest->paused && !keys.toggle_pause) frames.push_back(protocol::encode_pause(true));
    frames.push_back(protocol::encode_step(1));
  }
  return frames;
}

}  // namespace fishtank::viewer
