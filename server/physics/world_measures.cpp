#include "server/physics/world_measures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace fishtank {

double ball_energy(const Float4& pos, const Float4& vel, float gravity) {
  const double speed2 = double(vel.x) * vel.x + double(vel.y) * vel.y + double(vel.z) * vel.z;
  return 0.5 * vel.w * speed2 + double(vel.w) * gravity * pos.y;
}

double mean_neighbours(const World& world) {
  const NeighbourList& list = world.neighbour_list();
  const std::uint32_t n = world.ball_count();
  if (n == 0 || list.stride() == 0) return 0.0;
  double sum = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) sum += list.counts()[i];
  return sum / n;
}

double kinetic_energy(const World& world) {
  const Float4 *pos = world.positions(), *vel = world.velocities();
  double e = 0.0;
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) e += ball_energy(pos[i], vel[i], 0.0f);
  return e;
}

float max_speed(const World& world) {
  const Float4* vel = world.velocities();
  float fastest2 = 0.0f;
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) fastest2 = std::max(fastest2, squared_length3(vel[i]));
  return std::sqrt(fastest2);
}

double potential_energy(const World& world) {
  const Float4 *pos = world.positions(), *vel = world.velocities();  // vel's w is the mass
  const float gravity = world.model().gravity;
  double e = 0.0;
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) e += double(vel[i].w) * gravity * pos[i].y;
  return e;
}

double elastic_energy(const World& world) {
  if (!world.lists_current()) return 0.0;  // no lists yet: nothing has been stepped
  const TankBounds& t = world.params().tank;
  const Float4* pos = world.positions();
  double sum_x2 = 0.0;
  world.neighbour_list().for_each_list([&](std::uint32_t i, ListView list) {
    const Float4& p = pos[i];
    for (std::uint32_t n = 0; n < list.count; ++n) {
      const Float4& q = pos[list[n]];
      double dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z;
      double overlap = p.w + q.w - std::sqrt(dx * dx + dy * dy + dz * dz);
      if (overlap > 0.0) sum_x2 += 0.5 * overlap * overlap;  // each pair is listed from both sides
    }
  });
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) {
    const Float4& p = pos[i];
    for (double overlap : {t.min.x + p.w - p.x, p.x + p.w - t.max.x, t.min.y + p.w - p.y, p.y + p.w - t.max.y,
                           t.min.z + p.w - p.z, p.z + p.w - t.max.z})
      if (overlap > 0.0) sum_x2 += overlap * overlap;
  }
  return 0.5 * world.model().k * sum_x2;
}

std::string overlap_warning(const World& world) {
  const float overlap = max_overlap_fraction(world);
  const double energy_per_ball = world.ball_count() ? kinetic_energy(world) / world.ball_count() : 0.0;
  if (!resting_overlap_too_deep(overlap, energy_per_ball)) return "";
  char text[160];
  std::snprintf(text, sizeof text,
                "largest resting overlap %.0f %% of the smaller radius (over %.0f %%): k = %g N/m is too soft",
                100.0 * overlap, 100.0 * kOverlapWarning, double(world.model().k));
  return text;
}

ContactFigures contact_figures(const World& world) {
  ContactFigures figures;
  const TankBounds& t = world.params().tank;
  const Float4* pos = world.positions();
  // The neighbour list holds every touching pair (stale only between a spawn and the next step).
  if (world.lists_current()) {
    std::uint32_t sides = 0;  // each pair is listed from both sides
    world.neighbour_list().for_each_list([&](std::uint32_t i, ListView list) {
      const Float4& p = pos[i];
      for (std::uint32_t n = 0; n < list.count; ++n) {
        const Float4& q = pos[list[n]];
        const float dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z, reach = p.w + q.w;
        const float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 >= reach * reach) continue;  // a gap: no contact, no overlap
        ++sides;
        figures.max_overlap = std::max(figures.max_overlap, (reach - std::sqrt(d2)) / std::min(p.w, q.w));
      }
    });
    figures.contacts = sides / 2;
  }
  const bool counting = world.lists_current();  // the contacts count from the first step on
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) {
    const Float4& p = pos[i];
    const float walls[6] = {t.min.x + p.w - p.x, p.x + p.w - t.max.x, t.min.y + p.w - p.y,
                            p.y + p.w - t.max.y, t.min.z + p.w - p.z, p.z + p.w - t.max.z};
    for (const float overlap : walls) {
      figures.contacts += counting && overlap > 0.0f;
      figures.max_overlap = std::max(figures.max_overlap, overlap / p.w);
    }
  }
  return figures;
}

float max_overlap_fraction(const World& world) { return contact_figures(world).max_overlap; }

float pile_top(const World& world) {
  const Float4* pos = world.positions();
  float top = world.params().tank.min.y;
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) top = std::max(top, pos[i].y + pos[i].w);
  return top;
}

std::uint32_t escaped_or_invalid(const World& world) {
  const TankBounds& t = world.params().tank;
  const Float4 *pos = world.positions(), *vel = world.velocities();
  std::uint32_t bad = 0;
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) {
    const Float4& p = pos[i];
    const Float4& v = vel[i];
    bool inside = p.x >= t.min.x && p.x <= t.max.x && p.y >= t.min.y && p.y <= t.max.y && p.z >= t.min.z &&
                  p.z <= t.max.z;  // false for NaN
    bool finite = std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    if (!inside || !finite) ++bad;
  }
  return bad;
}

std::vector<std::uint32_t> indices_by_id(const World& world) {
  std::vector<std::uint32_t> by_id(world.ball_count());
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) by_id[world.ids()[i]] = i;
  return by_id;
}

std::uint64_t state_hash(const World& world) {
  const Float4 *pos = world.positions(), *vel = world.velocities();
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* data, std::size_t bytes) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) h = (h ^ b[k]) * 1099511628211ull;
  };
  for (std::uint32_t i : indices_by_id(world)) {
    mix(&pos[i], sizeof(Float4));
    mix(&vel[i], sizeof(Float4));
  }
  return h;
}

}  // namespace fishtank
