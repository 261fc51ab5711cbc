#include "viewer/net/interpolation.h"

#include <algorithm>

#include "viewer/render/math.h"

namespace fishtank::viewer {

int interpolate(const RenderPair& pair, const ServerInfo& info, std::vector<SphereInstance>& out) {
  const Snapshot& a = *pair.from;
  const Snapshot& b = *pair.to;
  const float t = pair.alpha;
  const std::vector<std::uint8_t>& kinds = *b.kinds;
  const TankBounds& tank = b.tank;  // a pair never spans two scene starts (NetClient clears the buffer)
  const Vec3 scale = tank.size() * (1.0f / 65535.0f);

  // Radius and colour per kind, looked up once rather than per ball.
  std::vector<SphereInstance> look(info.kinds.size());
  for (std::size_t k = 0; k < look.size(); ++k) {
    const BallKind& kind = info.kinds[k];
    look[k] = {0, 0, 0, 0.5f * kind.diameter, {kind.rgb[0], kind.rgb[1], kind.rgb[2], 255}};
  }

  out.clear();
  out.reserve(b.ball_count + b.players.size());
  // Quantised coordinates are blended before scaling: one multiply-add per axis.
  // Balls that are new in `to` have no earlier position and appear where they are.
  const std::uint32_t both = std::min(a.ball_count, b.ball_count);
  const std::uint16_t* qa = a.quantised.data();
  const std::uint16_t* qb = b.quantised.data();
  for (std::uint32_t i = 0; i < b.ball_count; ++i) {
    const std::uint16_t* p = qb + 3 * i;
    const std::uint16_t* q = i < both ? qa + 3 * i : p;
    SphereInstance s = look[kinds[i]];
    s.x = tank.min.x + (q[0] + (static_cast<float>(p[0]) - q[0]) * t) * scale.x;
    s.y = tank.min.y + (q[1] + (static_cast<float>(p[1]) - q[1]) * t) * scale.y;
    s.z = tank.min.z + (q[2] + (static_cast<float>(p[2]) - q[2]) * t) * scale.z;
    out.push_back(s);
  }

  int own = -1;
  for (const PlayerState& pb : b.players) {
    Vec3 pos = pb.pos;
    auto pa =
        std::find_if(a.players.begin(), a.players.end(), [&](const PlayerState& p) { return p.id == pb.id; });
    if (pa != a.players.end()) pos = lerp(pa->pos, pb.pos, t);
    if (info.has_player && pb.id == info.player_id) own = static_cast<int>(out.size());
    out.push_back({pos.x, pos.y, pos.z, 0.5f * kPlayerDiameter, {255, 255, 255, 255}});
  }
  return own;
}

}  // namespace fishtank::viewer
