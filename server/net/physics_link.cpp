#include "server/net/physics_link.h"

#include <string>

namespace fishtank::net {

namespace {
template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;
}  // namespace

PhysicsLink::PhysicsLink(CommandQueue& queue, const std::atomic<int>& viewers, PhysicsLinkOptions options,
                         std::function<void(Reply)> reply, std::function<void(SharedSnapshot)> publish)
    : queue_(queue), viewers_(viewers), options_(options), reply_(std::move(reply)), publish_(std::move(publish)) {}

void PhysicsLink::at_step_boundary(World& world, const LoopStatus& status) {
  queue_.drain(drained_);
  for (const Command& command : drained_) apply(world, command);

  const Clock::time_point now = Clock::now();
  if (now < next_snapshot_) return;
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / options_.snapshot_rate_hz));
  // Keep the phase, but never try to catch up on missed snapshots in a burst.
  next_snapshot_ = std::max(next_snapshot_ + period, now);
  if (viewers_.load(std::memory_order_relaxed) > 0) publish_snapshot(world, status);
}

void PhysicsLink::apply(World& world, const Command& command) {
  const std::uint32_t client = command.client_id;
  std::visit(Overloaded{
                 [&](const JoinCommand& join) {
                   JoinedReply joined;
                   if (join.wants_player) {
                     if (world.player_count() < options_.max_players) {
                       joined.player_id = world.add_player();
                       player_of_client_[client] = *joined.player_id;
                     } else {
                       joined.refusal = "all " + std::to_string(options_.max_players) +
                                        " player spheres are taken (--max-players); you are observing";
                     }
                   }
                   reply_({client, std::move(joined)});
                 },
                 [&](const LeaveCommand&) {
                   if (auto it = player_of_client_.find(client); it != player_of_client_.end()) {
                     world.remove_player(it->second);
                     player_of_client_.erase(it);
                   }
                 },
                 [&](const SetVelocityCommand& set) {
                   // Clients without a sphere have nothing to move; the decoder already refused NaN.
                   if (auto it = player_of_client_.find(client); it != player_of_client_.end())
                     world.set_player_velocity(it->second, set.velocity);
                 },
                 [&](const AddBallsCommand& add) {
                   AddResult added = world.add_balls(add.count);
                   reply_({client, BallsAddedReply{std::move(added.refusal)}});
                 },
             },
             command.action);
}

void PhysicsLink::publish_snapshot(const World& world, const LoopStatus& status) {
  const Clock::time_point start = Clock::now();
  protocol::SnapshotHeader header;
  header.tick = tick_++;
  header.sim_time = world.time();
  header.physics_steps = static_cast<std::uint32_t>(world.steps());
  header.steps_per_s = static_cast<float>(status.steps_per_s);
  header.load = static_cast<float>(status.load);
  header.threads_stepping = static_cast<std::uint32_t>(status.threads);
  header.time_scale = static_cast<float>(status.time_scale);
  SharedSnapshot snapshot = encoder_.encode(world, header);
  stats_.encode_seconds += std::chrono::duration<double>(Clock::now() - start).count();
  ++stats_.encoded;
  publish_(std::move(snapshot));
}

}  // namespace fishtank::net
