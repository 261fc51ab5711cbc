#include "server/net/physics_link.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <string>

#include "common/cpu_clock.h"
#include "server/physics/world_measures.h"

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
                         RunControl& control, ActiveScene& scene, std::function<void(Reply)> reply,
                         std::function<void(SharedSnapshot)> publish)
    : queue_(queue),
      viewers_(viewers),
      options_(options),
      control_(control),
      scene_(scene),
      reply_(std::move(reply)),
      publish_(std::move(publish)) {}

void PhysicsLink::at_step_boundary(World& world, const LoopStatus& status) {
  queue_.drain(drained_);
  // A reset replaces everything before it, so of a burst only the last is
  // carried out: a client repeating Reset cannot stall the physics for all.
  std::size_t last_reset = drained_.size();
  for (std::size_t i = 0; i < drained_.size(); ++i)
    if (std::holds_alternative<ResetCommand>(drained_[i].action)) last_reset = i;
  for (std::size_t i = 0; i < drained_.size(); ++i) {
    const Command& command = drained_[i];
    if (i == last_reset || !std::holds_alternative<ResetCommand>(command.action)) {
      apply(world, command);
    } else if (command.client_id != drained_[last_reset].client_id) {
      // Another client's switch must not pass for this one's (its own later Reset speaks for it).
      reply_({command.client_id,
              ControlRefusedReply{ControlRefusedReply::Why::superseded,
                                  "Reset not carried out: another client's Reset reached the server at the same "
                                  "moment, and of such a burst only the last is taken; send it again to have it"}});
    }
  }

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
                 [&](const JoinCommand& join) { this->join(world, client, join.wants_player); },
                 [&](const LeaveCommand&) { leave(world, client); },
                 [&](const SetVelocityCommand& set) {
                   // Clients without a sphere have nothing to move; the decoder already refused NaN.
                   if (auto it = player_of_client_.find(client); it != player_of_client_.end())
                     world.set_player_velocity(it->second, set.velocity);
                 },
                 [&](const AddBallsCommand& add) {
                   AddResult added = world.add_balls(add.count);
                   reply_({client, BallsAddedReply{std::move(added.refusal)}});
                 },
                 [&](const PauseCommand& pause) {
                   control_.paused = pause.paused;
                   if (!pause.paused) control_.steps_to_run = 0;
                 },
                 [&](const StepCommand& step) {
                   if (control_.paused)
                     control_.steps_to_run += step.count;
                   else
                     reply_({client, ControlRefusedReply{ControlRefusedReply::Why::not_paused,
                                                         "Step works only while paused; pause first"}});
                 },
                 [&](const ResetCommand& reset) {
                   const Clock::time_point start = Clock::now();
                   if (start < next_reset_) {
                     reply_({client, ControlRefusedReply{ControlRefusedReply::Why::too_soon,
                                                         "Reset refused: it came too soon after the last one "
                                                         "(restarts may take a fifth of the physics at most); "
                                                         "try again"}});
                     return;
                   }
                   // Asked-for steps belonged to the old start; a pause holds the new one still.
                   control_.steps_to_run = 0;
                   std::string refusal = scene_.start(world, reset.scene, reset.seed);
                   if (!scene_.limit_note().empty()) spdlog::warn("{}", scene_.limit_note());
                   const Clock::time_point end = Clock::now();
                   next_reset_ = end + kResetSpacing * (end - start);
                   if (!refusal.empty())
                     reply_({client, ControlRefusedReply{ControlRefusedReply::Why::fewer_balls, std::move(refusal)}});
                 },
                 [&](const TimeScaleCommand& scale) { control_.time_scale = scale.scale; },
             },
             command.action);
}

void PhysicsLink::join(World& world, std::uint32_t client, bool wants_player) {
  JoinedReply joined;
  bool queued = false;
  if (wants_player && options_.max_players == 0) {
    joined.refusal = "this server has no player spheres (--max-players 0); you are observing";
  } else if (wants_player && world.player_count() < options_.max_players) {
    joined.player_id = world.add_player();
    player_of_client_[client] = *joined.player_id;
  } else if (wants_player) {
    queued = true;
    waiting_for_player_.push_back(client);
    joined.refusal =
        (options_.max_players == 1 ? std::string("the one player sphere is taken")
                                   : "all " + std::to_string(options_.max_players) + " player spheres are taken") +
        " (--max-players); you are observing, in line for the next one freed";
  }
  reply_({client, std::move(joined)});
  if (queued) tell_places_from(waiting_for_player_.size() - 1);
}

void PhysicsLink::tell_places_from(std::size_t first) {
  for (std::size_t i = first; i < waiting_for_player_.size(); ++i)
    reply_({waiting_for_player_[i], InLineReply{static_cast<std::uint32_t>(i)}});
}

void PhysicsLink::leave(World& world, std::uint32_t client) {
  // Leave ends a session, or frees an unmoved sphere (player_idle) while the client stays.
  const auto waiting = std::find(waiting_for_player_.begin(), waiting_for_player_.end(), client);
  if (waiting != waiting_for_player_.end()) {
    const auto place = static_cast<std::size_t>(waiting - waiting_for_player_.begin());
    waiting_for_player_.erase(waiting);
    tell_places_from(place);
  }
  const auto it = player_of_client_.find(client);
  if (it == player_of_client_.end()) return;
  world.remove_player(it->second);
  player_of_client_.erase(it);
  if (waiting_for_player_.empty()) return;
  const std::uint32_t next = waiting_for_player_.front();
  waiting_for_player_.pop_front();
  const std::uint32_t player_id = world.add_player();
  player_of_client_[next] = player_id;
  reply_({next, PlayerGrantedReply{player_id}});
  tell_places_from(0);
}

void PhysicsLink::refresh_figures(const World& world, Clock::time_point now) {
  // Paused, with the asked steps done, the state holds until the next command: its figures are measured
  // at once, or a script stepping faster than the period would read the figures of an earlier step.
  const bool stepped_to_rest = control_.paused && control_.steps_to_run == 0 && world.steps() != figures_step_;
  if (now < next_figures_ && figures_start_ == scene_.start_count() && !stepped_to_rest) return;
  figures_start_ = scene_.start_count();
  figures_step_ = world.steps();
  kinetic_energy_per_ball_ = world.ball_count() ? static_cast<float>(kinetic_energy(world) / world.ball_count()) : 0.0f;
  const ContactFigures contact = contact_figures(world);
  contacts_ = contact.contacts;
  max_overlap_ = contact.max_overlap;
  next_figures_ = now + std::max<Clock::duration>(kFiguresPeriod, kFiguresSpacing * (Clock::now() - now));
}

void PhysicsLink::publish_snapshot(const World& world, const LoopStatus& status) {
  const Clock::time_point start = Clock::now();
  const double cpu_start = thread_cpu_seconds();
  protocol::SnapshotHeader header;
  header.tick = tick_++;
  header.sim_time = world.time();
  header.physics_steps = static_cast<std::uint32_t>(world.steps());
  header.steps_per_s = static_cast<float>(status.steps_per_s);
  header.load = static_cast<float>(status.load);
  header.threads_stepping = static_cast<std::uint32_t>(status.threads);
  header.time_scale = static_cast<float>(status.time_scale);
  header.paused = control_.paused;
  header.time_scale_set = static_cast<float>(control_.time_scale);
  header.scene = scene_.name();
  header.scene_start = scene_.start_count();
  header.tank = world.params().tank;
  refresh_figures(world, start);
  header.kinetic_energy_per_ball = kinetic_energy_per_ball_;
  header.contacts = contacts_;
  header.max_overlap = max_overlap_;
  SharedSnapshot snapshot = encoder_.encode(world, header);
  stats_.encode_seconds += std::chrono::duration<double>(Clock::now() - start).count();
  stats_.encode_cpu_seconds += thread_cpu_seconds() - cpu_start;
  ++stats_.encoded;
  publish_(std::move(snapshot));
}

}  // namespace fishtank::net
