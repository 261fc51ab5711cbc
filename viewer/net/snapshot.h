#pragma once
// What the viewer keeps of the server's messages, decoded from FlatBuffers by
// the net thread into plain structs that the render thread reads without
// knowing the wire format.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/tank.h"

namespace fishtank::viewer {

// From Welcome: fixed for the life of one connection.
struct ServerInfo {
  std::string variant;  // "sse" or "scalar"
  std::string simd;     // e.g. "sse4.1"
  int threads = 0;      // worker threads at most; Snapshot::threads_stepping says how many step now
  TankBounds tank;
  float dt = 0.0f;
  float steps_per_contact = 0.0f;  // contact duration of the lightest pair / dt; 0: not reported
  float tolerance = 0.0f;          // the per-collision error dt was chosen for; 0: dt given
  std::vector<BallKind> kinds;     // indexed by a ball's kind number
  std::uint32_t client_id = 0;
  std::string control_policy;          // who may pause, step, reset, switch scene, set the time scale
  bool may_control = false;            // whether this viewer may
  bool observers_may_control = false;  // whether it may without a sphere (once the server frees its own)
  std::uint32_t player_id = 0;
  bool has_player = false;
  // Without a sphere, the server's reason (player_limit: in line for one; player_idle: it was freed).
  std::string observing;
  std::optional<std::uint32_t> ahead_in_line;  // in line for a sphere: clients before this viewer (InLine)
};

struct PlayerState {
  std::uint32_t id;
  Vec3 pos;
};

struct Snapshot {
  std::uint64_t tick = 0;
  double sim_time = 0.0;  // server seconds
  double received = 0.0;  // local steady-clock seconds, when it arrived
  float steps_per_s = 0.0f;
  float load = 0.0f;
  std::uint32_t threads_stepping = 0;  // 0: the server did not say
  float time_scale = 0.0f;             // simulated seconds per wall second; 0: the server did not say
  bool paused = false;
  float time_scale_set = 0.0f;  // asked for (SetTimeScale); 0: the server did not say
  std::string scene;
  std::uint32_t scene_start = 0;         // +1 per scene (re)start: ball ids restart at 0
  float kinetic_energy_per_ball = 0.0f;  // joules
  std::uint32_t contacts = 0;
  float max_overlap = 0.0f;  // fraction of the smaller radius (Snapshot.max_overlap)
  TankBounds tank;           // the scene's: the quantisation bounds (Welcome's when the server did not say)
  std::uint32_t ball_count = 0;
  // x, y, z per ball in id order, each 0..65535 over the tank bounds.
  std::vector<std::uint16_t> quantised;
  // Kind of every ball so far, id order. Shared between snapshots and copied
  // only when new balls appear (sizes are sent once per ball, SPEC 3.6).
  std::shared_ptr<const std::vector<std::uint8_t>> kinds;
  std::vector<PlayerState> players;
};

}  // namespace fishtank::viewer
