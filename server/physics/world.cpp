#include "server/physics/world.h"

#include <algorithm>
#include <cstdio>

#include "common/fp_env.h"
#include "server/physics/world_measures.h"

namespace fishtank {

namespace {

constexpr float kPackingLimit = 0.6f;
constexpr Float4 kGhostVel{0.0f, 0.0f, 0.0f, 1.0f};  // mass 1: the same as vel_ and as a half-step row

std::uint32_t capacity_of(const TankBounds& tank) {
  return static_cast<std::uint32_t>(kPackingLimit * tank.volume() / mean_ball_volume());
}

}  // namespace

World::World(const PhysicsParams& params, const Kernels& kernels, int threads, std::uint64_t seed)
    : params_(params),
      model_(make_contact_model(params)),
      kernels_(kernels),
      pool_(kernels.threaded ? threads : 1, kStepBatch),
      spawner_(params.tank, seed) {
  enable_flush_denormals_to_zero();
  list_.configure(params.tank, starting_skin(params));
  capacity_ = capacity_of(params.tank);
  max_balls_ = capacity_;
  chunk_moved_.resize(pool_.max_chunks());
  chunk_missing_.resize(pool_.max_chunks());
  chunk_longest_.resize(pool_.max_chunks());
  resize(0);
}

void World::resize(std::uint32_t n) {
  n_ = n;
  for (auto* v : {&pos_, &vel_, &vel_half_, &vel_half_before_, &pos_next_, &vel_half_next_, &acc_, &pos_at_build_})
    v->resize(n + kGhostSlots);
  kind_.resize(n);
  id_.resize(n);
  stray_balls_.resize(n);
  set_ghost();
}

void World::set_ghost() {
  for (std::uint32_t g = n_; g < n_ + kGhostSlots; ++g) {
    pos_[g] = pos_next_[g] = pos_at_build_[g] = kGhostPos;
    vel_[g] = vel_half_[g] = vel_half_before_[g] = vel_half_next_[g] = kGhostVel;
    acc_[g] = Float4{};
  }
}

AddResult World::add_balls(std::int64_t count) {
  AddResult result;
  const std::int64_t room = std::max<std::int64_t>(0, std::int64_t(max_balls_) - n_ - spawner_.pending());
  if (count <= 0) {
    result.refusal = "asked to add " + std::to_string(count) + " balls; the count must be positive";
    return result;
  }
  result.accepted = static_cast<std::uint32_t>(std::min(count, room));
  spawner_.enqueue(result.accepted);
  if (result.accepted < count)
    result.refusal = "added " + std::to_string(result.accepted) + " of " + std::to_string(count) +
                     " balls: the tank holds at most " + std::to_string(max_balls_) + " (" + std::to_string(n_) +
                     " in it, " + std::to_string(spawner_.pending() - result.accepted) + " already queued)";
  return result;
}

void World::place_ball(int kind, Vec3 p, Vec3 v) {
  derive_velocities();  // the others' velocities become the start of the next pass
  const BallKind& k = kBallKinds.at(kind);
  std::uint32_t i = n_;
  resize(n_ + 1);
  pos_[i] = {p.x, p.y, p.z, 0.5f * k.diameter};
  vel_[i] = {v.x, v.y, v.z, k.mass};
  kind_[i] = static_cast<std::uint8_t>(kind);
  id_[i] = next_id_++;
  energy_added_ += ball_energy(pos_[i], vel_[i], model_.gravity);
  needs_rebuild_ = true;
  needs_initial_forces_ = true;
}

void World::restart(const TankBounds& tank, std::uint64_t seed) {
  params_.tank = tank;
  list_.configure(tank, starting_skin(params_));  // a restarted scene steps as a new one would
  spawner_ = Spawner(tank, seed);
  capacity_ = capacity_of(tank);
  max_balls_ = capacity_;
  resize(0);
  next_id_ = 0;
  energy_added_ = 0.0;
  vel_stale_ = false;
  strayed_listed_ = false;
  needs_initial_forces_ = false;
  needs_rebuild_ = true;
}

std::string World::set_max_balls(std::uint32_t max_balls) {
  if (max_balls <= capacity_) {
    max_balls_ = max_balls;
    return "";
  }
  char text[160];
  std::snprintf(text, sizeof text,
                "the tank holds at most %u balls of the default mix (packing fraction %.2g); asked for %u", capacity_,
                double(kPackingLimit), max_balls);
  return text;
}

void World::spawn() {
  PhaseTimer timer(phase_seconds_.spawn);
  derive_velocities();  // while vel_half_ and vel_half_next_ are still the last pass's
  placed_.clear();
  spawner_.place(params_.tank, pos_.data(), n_, player_pos_.data(), static_cast<int>(player_pos_.size()), placed_);
  if (placed_.empty()) return;
  std::uint32_t first = n_;
  resize(n_ + static_cast<std::uint32_t>(placed_.size()));
  for (std::size_t b = 0; b < placed_.size(); ++b) {
    std::uint32_t i = first + static_cast<std::uint32_t>(b);
    pos_[i] = placed_[b].pos;
    vel_[i] = placed_[b].vel;
    kind_[i] = static_cast<std::uint8_t>(placed_[b].kind);
    id_[i] = next_id_++;
    energy_added_ += ball_energy(pos_[i], vel_[i], model_.gravity);
    // A spawned ball touches nothing, so gravity is its whole acceleration (and the lists are rebuilt).
    kick_drift(i, Float4{0.0f, -model_.gravity, 0.0f, 0.0f});
  }
  needs_rebuild_ = true;
}

// v(t) is the mean of vel_half = v(t - dt/2) and vel_half_next = v(t + dt/2): derived for observers,
// who look a few dozen times a second, instead of stored by every step.
void World::derive_velocities() const {
  if (!vel_stale_) return;
  for (std::uint32_t i = 0; i < n_; ++i) {
    const Float4 before = vel_half_[i], after = vel_half_next_[i];
    const float mass = kBallKinds[kind_[i]].mass;  // the rows carry 1 / mass
    vel_[i] = {0.5f * (before.x + after.x), 0.5f * (before.y + after.y), 0.5f * (before.z + after.z), mass};
  }
  vel_stale_ = false;
}

const Float4* World::velocities() const {
  derive_velocities();
  return vel_.data();
}

BallView World::ball(std::uint32_t id) const {
  derive_velocities();
  for (std::uint32_t i = 0; i < n_; ++i)
    if (id_[i] == id) return {pos_[i], vel_[i], kind_[i]};
  return {Float4{}, Float4{}, -1};
}

}  // namespace fishtank
