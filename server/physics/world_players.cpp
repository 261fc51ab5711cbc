// The world's player spheres: kinematic, moved where they are told, pushing
// every ball they touch.

#include <algorithm>
#include <cmath>

#include "server/physics/player_spawn.h"
#include "server/physics/world.h"

namespace fishtank {

void World::respawn_players() {
  derive_velocities();
  for (std::size_t p = 0; p < player_pos_.size(); ++p) {
    // Avoids the players placed before it in this loop, not the old places of the others.
    const Vec3 at = choose_player_spawn(params_.tank, player_pos_.data(), p, pos_.data(), n_);
    player_pos_[p] = {at.x, at.y, at.z, 0.5f * kPlayerDiameter};
    player_vel_[p] = {};
  }
  if (n_ > 0) needs_initial_forces_ = true;  // a ball a player now touches feels it from the next step's first kick
}

std::uint32_t World::add_player() {
  std::uint32_t id = next_player_id_++;
  const Vec3 at = choose_player_spawn(params_.tank, player_pos_.data(), player_pos_.size(), pos_.data(), n_);
  player_ids_.push_back(id);
  player_pos_.push_back({at.x, at.y, at.z, 0.5f * kPlayerDiameter});
  player_vel_.push_back({});
  return id;
}

bool World::remove_player(std::uint32_t id) {
  auto it = std::find(player_ids_.begin(), player_ids_.end(), id);
  if (it == player_ids_.end()) return false;
  auto k = it - player_ids_.begin();
  player_ids_.erase(it);
  player_pos_.erase(player_pos_.begin() + k);
  player_vel_.erase(player_vel_.begin() + k);
  return true;
}

bool World::set_player_velocity(std::uint32_t id, Vec3 v) {
  auto it = std::find(player_ids_.begin(), player_ids_.end(), id);
  if (it == player_ids_.end() || !is_finite(v)) return false;
  // In double: a finite float velocity's squared length can overflow a float.
  const double speed = std::sqrt(double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z);
  if (speed > params_.player_max_speed) v = v * static_cast<float>(params_.player_max_speed / speed);
  player_vel_[it - player_ids_.begin()] = {v.x, v.y, v.z, 0.0f};
  return true;
}

Vec3 World::player_position(std::uint32_t id) const {
  auto it = std::find(player_ids_.begin(), player_ids_.end(), id);
  if (it == player_ids_.end()) return {};
  const Float4& p = player_pos_[it - player_ids_.begin()];
  return {p.x, p.y, p.z};
}

void World::move_players() {
  // Kinematic: the sphere goes where it is told, stopping at the walls.
  const TankBounds& t = params_.tank;
  for (std::size_t p = 0; p < player_pos_.size(); ++p) {
    Float4& pos = player_pos_[p];
    Float4& vel = player_vel_[p];
    float* x[3] = {&pos.x, &pos.y, &pos.z};
    float* v[3] = {&vel.x, &vel.y, &vel.z};
    const float lo[3] = {t.min.x, t.min.y, t.min.z}, hi[3] = {t.max.x, t.max.y, t.max.z};
    for (int a = 0; a < 3; ++a) {
      *x[a] += *v[a] * model_.dt;
      if (*x[a] < lo[a] + pos.w || *x[a] > hi[a] - pos.w) {
        *x[a] = std::clamp(*x[a], lo[a] + pos.w, hi[a] - pos.w);
        *v[a] = 0.0f;
      }
    }
  }
}

}  // namespace fishtank
