#include "server/physics/spawner.h"

#include <algorithm>
#include <cmath>

namespace fishtank {

namespace {
constexpr float kClearance = 0.01f;  // gap kept between a new ball and anything else
}

Spawner::Spawner(const TankBounds& tank, std::uint64_t seed) : rng_(seed) {
  Vec3 size = tank.size();
  slots_x_ = std::max(1, static_cast<int>(size.x / kMaxBallDiameter));
  slots_z_ = std::max(1, static_cast<int>(size.z / kMaxBallDiameter));
  slot_edge_x_ = size.x / slots_x_;
  slot_edge_z_ = size.z / slots_z_;
  slot_order_.resize(std::size_t(slots_x_) * slots_z_);
  near_top_.resize(slot_order_.size());
}

float Spawner::uniform() { return static_cast<float>(rng_() >> 40) * (1.0f / 16777216.0f); }

void Spawner::enqueue(std::uint32_t count) {
  for (std::uint32_t i = 0; i < count; ++i) {
    queue_.push_back(next_kind_);
    next_kind_ = (next_kind_ + 1) % kKindCount;
  }
}

void Spawner::place(const TankBounds& tank, const Float4* pos, std::uint32_t n, const Float4* players, int player_count,
                    std::vector<NewBall>& placed) {
  if (queue_.empty()) return;
  const float entry_floor = tank.max.y - kMaxBallDiameter - kClearance;
  auto slot_of = [&](float x, float z) {
    int sx = std::clamp(static_cast<int>((x - tank.min.x) / slot_edge_x_), 0, slots_x_ - 1);
    int sz = std::clamp(static_cast<int>((z - tank.min.z) / slot_edge_z_), 0, slots_z_ - 1);
    return sx + slots_x_ * sz;
  };

  for (auto& balls : near_top_) balls.clear();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (pos[i].y + pos[i].w > entry_floor || !std::isfinite(pos[i].y))
      near_top_[slot_of(pos[i].x, pos[i].z)].push_back(i);
  }

  auto overlaps = [](const Float4& a, const Float4& b) {
    float dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
    float reach = a.w + b.w + kClearance;
    return !(dx * dx + dy * dy + dz * dz >= reach * reach);  // NaN counts as overlapping
  };
  auto is_free = [&](const Float4& candidate, int slot) {
    int sx = slot % slots_x_, sz = slot / slots_x_;
    for (int z = std::max(sz - 1, 0); z <= std::min(sz + 1, slots_z_ - 1); ++z)
      for (int x = std::max(sx - 1, 0); x <= std::min(sx + 1, slots_x_ - 1); ++x)
        for (std::uint32_t j : near_top_[x + slots_x_ * z])
          if (overlaps(candidate, pos[j])) return false;
    for (int p = 0; p < player_count; ++p)
      if (overlaps(candidate, players[p])) return false;
    for (std::size_t b = first_placed_; b < placed.size(); ++b)
      if (overlaps(candidate, placed[b].pos)) return false;
    return true;
  };

  first_placed_ = placed.size();
  for (std::size_t s = 0; s < slot_order_.size(); ++s) slot_order_[s] = static_cast<std::uint32_t>(s);
  for (std::size_t s = slot_order_.size(); s > 1; --s)
    std::swap(slot_order_[s - 1], slot_order_[static_cast<std::size_t>(uniform() * s)]);

  for (std::uint32_t slot : slot_order_) {
    if (queue_.empty()) break;
    const BallKind& kind = kBallKinds[queue_.front()];
    const float r = 0.5f * kind.diameter;
    const float slack_x = std::max(0.0f, 0.5f * slot_edge_x_ - r - kClearance);
    const float slack_z = std::max(0.0f, 0.5f * slot_edge_z_ - r - kClearance);
    const int sx = static_cast<int>(slot) % slots_x_, sz = static_cast<int>(slot) / slots_x_;
    Float4 candidate{tank.min.x + (sx + 0.5f) * slot_edge_x_ + slack_x * (2.0f * uniform() - 1.0f),
                     tank.max.y - r - kClearance,
                     tank.min.z + (sz + 0.5f) * slot_edge_z_ + slack_z * (2.0f * uniform() - 1.0f), r};
    if (!is_free(candidate, static_cast<int>(slot))) continue;
    placed.push_back({queue_.front(), candidate, Float4{0.0f, -kEntrySpeed, 0.0f, kind.mass}});
    queue_.pop_front();
  }
}

}  // namespace fishtank
