#pragma once
// What network threads ask of the physics thread, and what it answers.
//
//   io thread ──push(Command)──► CommandQueue ──drain()──► physics thread
//   io thread ◄──post(Reply)─────────────────────────────── (at a step boundary)
//
// The queue is the only state both threads touch; its mutex is held for a
// push_back or a swap, never while the world steps.

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "common/vec3.h"

namespace fishtank::net {

struct JoinCommand {
  bool wants_player = false;
};
struct LeaveCommand {};
struct SetVelocityCommand {
  Vec3 velocity;
};
struct AddBallsCommand {
  std::uint32_t count = 0;
};

// The sandbox's controls; the session has already checked the client may
// (ControlPolicy) and that the values are in range.
struct PauseCommand {
  bool paused = true;
};
struct StepCommand {
  std::uint32_t count = 0;
};
struct ResetCommand {
  std::optional<std::string> scene;   // empty: the scene running
  std::optional<std::uint64_t> seed;  // empty: the scene's last seed
};
struct TimeScaleCommand {
  float scale = 1.0f;
};

struct Command {
  std::uint32_t client_id = 0;
  std::variant<JoinCommand, LeaveCommand, SetVelocityCommand, AddBallsCommand, PauseCommand, StepCommand, ResetCommand,
               TimeScaleCommand>
      action;
};

struct JoinedReply {
  std::optional<std::uint32_t> player_id;  // empty: no sphere (not asked for, or all taken)
  std::string refusal;                     // why a sphere that was asked for was not given
};
// A sphere another client freed, for this client that asked for one and waited in line.
struct PlayerGrantedReply {
  std::uint32_t player_id = 0;
};
// This client's place in line for a sphere changed (or it just joined the line).
struct InLineReply {
  std::uint32_t ahead = 0;
};
struct BallsAddedReply {
  std::string refusal;  // empty when all were accepted; else how many were and why no more
};

// A control the physics thread could not fully carry out, and why; nothing is
// sent when it was done.
struct ControlRefusedReply {
  enum class Why {
    not_paused,   // a Step while running: nothing done
    fewer_balls,  // the scene started with fewer balls than asked
    too_soon,     // a Reset before the last one's spacing was up: nothing done
    superseded    // a Reset replaced by another client's later one at the same step boundary: nothing done
  };
  Why why = Why::not_paused;
  std::string refusal;
};

struct Reply {
  std::uint32_t client_id = 0;
  std::variant<JoinedReply, PlayerGrantedReply, InLineReply, BallsAddedReply, ControlRefusedReply> result;
};

// Bounded, so a client flooding commands faster than the physics drains them
// gets "server busy" instead of growing the server's memory.
class CommandQueue {
 public:
  static constexpr std::size_t kCapacity = 4096;

  // False when full (the command is dropped). Join and Leave are always
  // accepted: a session's lifetime must reach the physics thread.
  bool push(Command command) {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool lifecycle =
        std::holds_alternative<JoinCommand>(command.action) || std::holds_alternative<LeaveCommand>(command.action);
    if (!lifecycle && commands_.size() >= kCapacity) return false;
    commands_.push_back(std::move(command));
    return true;
  }

  // Everything queued so far, in order; `out` is cleared first (reuse it to avoid allocations).
  void drain(std::vector<Command>& out) {
    out.clear();
    std::lock_guard<std::mutex> lock(mutex_);
    out.swap(commands_);
  }

 private:
  std::mutex mutex_;
  std::vector<Command> commands_;
};

}  // namespace fishtank::net
