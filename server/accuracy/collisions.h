#pragma once
// One collision at a time, in the product's World: the measured restitution
// of every kind of contact (each size pair, a ball on a wall, a ball on the
// player sphere) against the contact model's exact answer. Without gravity
// that answer is e itself (overlap-ends definition, no clamp at zero force).

#include <string>
#include <vector>

#include "server/physics/kernels.h"
#include "server/physics/params.h"

namespace fishtank::accuracy {

enum class Body { kBall, kWall, kPlayer };
const char* body_name(Body b);  // "ball", "wall", "player"

struct CollisionCase {
  Body other;
  int kind_a, kind_b;  // kind_b: the other ball's, when other is kBall
  float speed;         // approach speed, m/s
  float phase;         // in [0, 1): where within a step the contact starts
};

// Every size pair, wall and player, at each speed and `phases` evenly spaced phases.
std::vector<CollisionCase> every_collision(const std::vector<float>& speeds, int phases);

// Rebound over approach normal speed, read once the bodies have parted.
float measured_restitution(const Kernels& kernels, const PhysicsParams& params, const CollisionCase& c);

struct CollisionErrors {
  int collisions = 0;
  int within_5e3 = 0;  // |measured - e| <= 0.005
  float worst = 0.0f;
  std::string worst_case;  // which collision, in words
};

// each: when given, every case's measured restitution, in the order of cases.
CollisionErrors sweep_collisions(const Kernels& kernels, const PhysicsParams& params,
                                 const std::vector<CollisionCase>& cases, std::vector<float>* each = nullptr);

// The sweep: e = 0.05, 0.3, 0.6, 0.9, 1; 0.1, 1, 5, 20 m/s; 20 phases.
inline const std::vector<float> kSweepRestitutions{0.05f, 0.3f, 0.6f, 0.9f, 1.0f};
inline const std::vector<float> kSweepSpeeds{0.1f, 1.0f, 5.0f, 20.0f};
constexpr int kSweepPhases = 20;

}  // namespace fishtank::accuracy
