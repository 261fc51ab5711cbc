#include "server/physics/player_spawn.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace fishtank {

namespace {

// Candidates lie on a cubic lattice around the centre, spaced wider than a
// player so that players on neighbouring points never touch.
constexpr float kSpacing = 1.5f * kPlayerDiameter;

// Gap between a player sphere at p and the sphere s (negative: they overlap).
float gap(Vec3 p, const Float4& s) {
  const Vec3 d{p.x - s.x, p.y - s.y, p.z - s.z};
  return length(d) - s.w - 0.5f * kPlayerDiameter;
}

}  // namespace

Vec3 choose_player_spawn(const TankBounds& tank, const Float4* players, std::size_t player_count, const Float4* balls,
                         std::size_t ball_count) {
  const Vec3 centre = tank.min + tank.size() * 0.5f;
  const float radius = 0.5f * kPlayerDiameter;
  // Fallback only when every candidate inside the tank touches a player.
  Vec3 best_any = centre;
  float best_any_room = -std::numeric_limits<float>::infinity();
  // The first shells of the lattice usually suffice; wider ones are tried only
  // when players fill the inner ones.
  for (int reach = 1;; ++reach) {
    std::vector<Vec3> candidates;
    for (int i = -reach; i <= reach; ++i)
      for (int j = -reach; j <= reach; ++j)
        for (int k = -reach; k <= reach; ++k) {
          const Vec3 p = centre + Vec3{static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)} * kSpacing;
          const Vec3 low = p - tank.min, high = tank.max - p;
          if (std::min({low.x, low.y, low.z, high.x, high.y, high.z}) >= radius) candidates.push_back(p);
        }
    // Nearest the centre first, so that equal room goes to the nearer point.
    std::stable_sort(candidates.begin(), candidates.end(),
                     [&](Vec3 a, Vec3 b) { return dot(a - centre, a - centre) < dot(b - centre, b - centre); });

    Vec3 best = centre;
    float best_room = -std::numeric_limits<float>::infinity();
    bool found = false;
    for (const Vec3& p : candidates) {
      const Vec3 low = p - tank.min, high = tank.max - p;
      float room = std::min({low.x, low.y, low.z, high.x, high.y, high.z}) - radius;
      float player_room = std::numeric_limits<float>::infinity();
      for (std::size_t q = 0; q < player_count; ++q) player_room = std::min(player_room, gap(p, players[q]));
      room = std::min(room, player_room);
      for (std::size_t b = 0; b < ball_count && room > best_room; ++b) room = std::min(room, gap(p, balls[b]));
      if (room > best_any_room) {
        best_any_room = room;
        best_any = p;
      }
      if (player_room >= 0.0f && room > best_room) {
        best_room = room;
        best = p;
        found = true;
      }
    }
    if (found) return best;
    // The lattice has outgrown the tank on every side: nothing free is left.
    const Vec3 half = tank.size() * 0.5f;
    if (reach * kSpacing > std::max({half.x, half.y, half.z})) return best_any;
  }
}

}  // namespace fishtank
