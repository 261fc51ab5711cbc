#include "server/accuracy/collisions.h"

#include <cmath>
#include <functional>
#include <sstream>

#include "server/physics/world.h"

namespace fishtank::accuracy {

std::vector<CollisionCase> every_collision(const std::vector<float>& speeds, int phases) {
  std::vector<CollisionCase> cases;
  const auto add = [&](Body other, int a, int b) {
    for (float speed : speeds)
      for (int p = 0; p < phases; ++p) cases.push_back({other, a, b, speed, float(p) / float(phases)});
  };
  for (int a = 0; a < kKindCount; ++a)
    for (int b = a; b < kKindCount; ++b) add(Body::kBall, a, b);
  for (int a = 0; a < kKindCount; ++a) add(Body::kWall, a, 0);
  for (int a = 0; a < kKindCount; ++a) add(Body::kPlayer, a, 0);
  return cases;
}

float measured_restitution(const Kernels& kernels, const PhysicsParams& params, const CollisionCase& c) {
  World world(params, kernels, 1, 1);
  const float ra = 0.5f * kBallKinds[c.kind_a].diameter;
  const float gap = c.speed * world.dt() * (2.0f + c.phase);  // closed in 2 + phase steps
  const TankBounds& t = params.tank;
  const Vec3 mid{0.5f * (t.min.x + t.max.x), 0.5f * (t.min.y + t.max.y), 0.5f * (t.min.z + t.max.z)};
  std::function<float()> separation;  // centre distance less the reach: < 0 while they overlap
  std::function<float()> rebound;
  if (c.other == Body::kBall) {
    const float rb = 0.5f * kBallKinds[c.kind_b].diameter;
    world.place_ball(c.kind_a, {mid.x - ra - 0.5f * gap, mid.y, mid.z}, {0.5f * c.speed, 0.0f, 0.0f});
    world.place_ball(c.kind_b, {mid.x + rb + 0.5f * gap, mid.y, mid.z}, {-0.5f * c.speed, 0.0f, 0.0f});
    separation = [&world, ra, rb] { return world.ball(1).pos.x - world.ball(0).pos.x - ra - rb; };
    rebound = [&world] { return world.ball(1).vel.x - world.ball(0).vel.x; };
  } else if (c.other == Body::kWall) {
    // The floor: positions near y = 0 resolve a slow contact's overlap finely in float.
    const float floor = params.tank.min.y;
    world.place_ball(c.kind_a, {mid.x, floor + ra + gap, mid.z}, {0.0f, -c.speed, 0.0f});
    separation = [&world, ra, floor] { return world.ball(0).pos.y - ra - floor; };
    rebound = [&world] { return world.ball(0).vel.y; };
  } else {
    const Vec3 centre = world.player_position(world.add_player());
    const float reach = ra + 0.5f * kPlayerDiameter;
    world.place_ball(c.kind_a, {centre.x + reach + gap, centre.y, centre.z}, {-c.speed, 0.0f, 0.0f});
    separation = [&world, reach, centre] { return world.ball(0).pos.x - centre.x - reach; };
    rebound = [&world] { return world.ball(0).vel.x; };
  }
  bool touched = false;
  for (int s = 0; s < 1000000; ++s) {
    world.step();
    touched = touched || separation() < 0.0f;
    if (touched && separation() > 0.0f) break;
  }
  for (int s = 0; s < 2; ++s) world.step();  // the step whose window held the parting is past
  return rebound() / c.speed;
}

const char* body_name(Body b) {
  static const char* const kNames[] = {"ball", "wall", "player"};
  return kNames[int(b)];
}

CollisionErrors sweep_collisions(const Kernels& kernels, const PhysicsParams& params,
                                 const std::vector<CollisionCase>& cases, std::vector<float>* each) {
  CollisionErrors out;
  for (const CollisionCase& c : cases) {
    const float measured = measured_restitution(kernels, params, c);
    if (each) each->push_back(measured);
    const float error = std::fabs(measured - params.restitution);
    ++out.collisions;
    out.within_5e3 += error <= 0.005f;
    if (error <= out.worst) continue;
    out.worst = error;
    std::ostringstream at;
    at << "diameter " << kBallKinds[c.kind_a].diameter << " on "
       << (c.other == Body::kBall ? "diameter " + std::to_string(int(kBallKinds[c.kind_b].diameter))
                                  : std::string(body_name(c.other)))
       << " at " << c.speed << " m/s, phase " << c.phase;
    out.worst_case = at.str();
  }
  return out;
}

}  // namespace fishtank::accuracy
