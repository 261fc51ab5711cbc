#pragma once
// The network's agent on the physics thread. Called by the realtime loop at
// every step boundary, it
//   1. applies the commands the sessions queued (join, leave, velocity, add balls,
//      and the sandbox's pause, step, reset and time scale) and hands each
//      answer back to the io thread; clients refused a sphere wait in line, and
//      a freed sphere goes to the first of them;
//   2. captures a snapshot when one is due (--snapshot-rate) and someone watches
//      (quantised once for every client; the io thread codes the frames).
// Nothing here runs on the io thread, so the world needs no lock.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <unordered_map>
#include <vector>

#include "server/net/commands.h"
#include "server/net/snapshot_encoder.h"
#include "server/realtime_loop.h"
#include "server/scenes/active_scene.h"

namespace fishtank::net {

struct PhysicsLinkOptions {
  double snapshot_rate_hz = 60.0;
  std::uint32_t max_players = 8;
};

// Measured on the physics thread; read there too (the status line).
struct SnapshotStats {
  std::uint64_t encoded = 0;
  double encode_seconds = 0.0;      // total, of the capture (quantisation) only
  double encode_cpu_seconds = 0.0;  // the same in the physics thread's CPU time
};

class PhysicsLink {
 public:
  // reply and publish are called on the physics thread and must only hand
  // their argument over to the io thread (post), never block.
  // control and scene belong to the physics thread too; they outlive this link.
  PhysicsLink(CommandQueue& queue, const std::atomic<int>& viewers, PhysicsLinkOptions options, RunControl& control,
              ActiveScene& scene, std::function<void(Reply)> reply, std::function<void(SharedSnapshot)> publish);

  void at_step_boundary(World& world, const LoopStatus& status);
  const SnapshotStats& snapshot_stats() const { return stats_; }

 private:
  using Clock = std::chrono::steady_clock;

  void apply(World& world, const Command& command);
  void join(World& world, std::uint32_t client, bool wants_player);
  void leave(World& world, std::uint32_t client);
  // Tells the clients in line from `first` on their place (each has moved up, or just joined).
  void tell_places_from(std::size_t first);
  void publish_snapshot(const World& world, const LoopStatus& status);
  // Refreshes the plotted figures (energy, contacts) when they are older than kFiguresPeriod, the scene
  // restarted, or paused steps came to an end.
  void refresh_figures(const World& world, Clock::time_point now);
  // The figures pass over every ball and contact on the physics thread while
  // the workers wait: ten times a second is plenty for a plot. A pass that
  // takes longer than a kFiguresSpacing-th of that waits kFiguresSpacing
  // times its cost instead, so watching a huge scene slows its physics by at
  // most that share.
  static constexpr std::chrono::milliseconds kFiguresPeriod{100};
  static constexpr int kFiguresSpacing = 20;
  // A restart costs what filling its scene costs; the next may come only
  // after this many times that, so however often clients ask, restarts take
  // at most a fifth of the physics thread.
  static constexpr int kResetSpacing = 4;

  CommandQueue& queue_;
  const std::atomic<int>& viewers_;
  PhysicsLinkOptions options_;
  RunControl& control_;
  ActiveScene& scene_;
  std::function<void(Reply)> reply_;
  std::function<void(SharedSnapshot)> publish_;

  std::vector<Command> drained_;
  std::unordered_map<std::uint32_t, std::uint32_t> player_of_client_;
  std::deque<std::uint32_t> waiting_for_player_;  // clients refused a sphere, first come first
  SnapshotEncoder encoder_;
  std::uint32_t tick_ = 0;
  Clock::time_point next_snapshot_ = Clock::now();
  SnapshotStats stats_;
  Clock::time_point next_figures_ = Clock::now();
  std::uint32_t figures_start_ = 0;  // the scene start they were measured in
  std::uint64_t figures_step_ = 0;   // and the step
  float kinetic_energy_per_ball_ = 0.0f;
  std::uint32_t contacts_ = 0;
  float max_overlap_ = 0.0f;
  Clock::time_point next_reset_ = Clock::time_point::min();
};

}  // namespace fishtank::net
