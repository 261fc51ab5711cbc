#pragma once
// Contact-model and time-step parameters, and the rules that derive one from
// another (documented in docs/technical-report.md, section 2.4).
//
//   damping ratio    zeta = -ln e / sqrt(pi^2 + ln^2 e)
//   pair damping     c    = 2 zeta sqrt(k m_eff),   m_eff = m1 m2 / (m1 + m2)
//   contact duration t_c  = pi sqrt(m_eff,min / k)   (undamped half period)
//   time step        dt   = t_c / n
//   steps per contact n    = ceil(sqrt(kToleranceRule / tolerance)), unless given
//
// The tolerance is the largest per-collision restitution error allowed. With
// the contact law of contact_law.h every collision's error is second order,
// at most kToleranceRule / n^2 over e = 0.05 ... 1, every pair, wall and player,
// 0.1 ... 20 m/s and any phase (fishtank-accuracy's collisions.csv measures it;
// docs/accuracy.md). Below 0.002 float32 positions set the floor for slow contacts.
//
// m_eff,min is the lightest pair's (two balls of the lightest kind; a wall or
// the player, being kinematic, gives a ball its own mass, twice that). Damping
// lengthens a contact (by 39 % at e = 0.05), but the damped oscillator's rates
// still have magnitude w0 = pi / t_c, so the undamped t_c sets dt.

#include <cstdint>
#include <limits>
#include <string>

#include "common/overlap.h"
#include "common/tank.h"

namespace fishtank {

struct PhysicsParams {
  float stiffness = 2.5e4f;   // k, N/m: keeps a full tank's largest overlap under 10 % of r_min
  float restitution = 0.6f;   // e, measured rebound / approach normal speed
  float tolerance = 0.005f;   // largest per-collision restitution error: sets n
  int steps_per_contact = 0;  // n in dt = t_c / n; 0: from the tolerance
  float dt = 0.0f;            // 0: derive from k; otherwise t_c / kMaxStepsPerContact ... t_c / kMinStepsPerContact
  float skin = 0.0f;          // neighbour-list skin, units; 0: follows the motion (World::adapt_skin)
  // Balls from which the SIMD step asks memory for rows ahead (World::beyond_cache); results never depend on it.
  // Below, the arrays stay in cache and asking costs instructions. The machine's reported cache sizes do not
  // place it (report 5.1): scripts/figures-prefetch measures where asking starts to pay.
  std::uint32_t prefetch_from = 32768;
  float gravity = 9.81f;           // m/s^2, along -y
  float player_max_speed = 10.0f;  // m/s; faster commands are clamped
  TankBounds tank;

  static constexpr int kMinStepsPerContact = 10;
  // Past this, a slow ball's step moves it less than float32 positions resolve.
  static constexpr int kMaxStepsPerContact = 100000;
  static constexpr float kToleranceRule = 0.8f;        // worst error times n^2, at most
  static constexpr float kTightestTolerance = 0.002f;  // float32 positions floor for a 0.1 m/s contact
  static constexpr float kLoosestTolerance = 0.0075f;  // 11 steps: the rule's margin over kMinStepsPerContact
  // The adaptive skin starts at kStartSkin and stays within [kMinSkin, kMaxSkin] (report 3.3).
  static constexpr float kStartSkin = 0.2f, kMinSkin = 0.1f, kMaxSkin = 1.0f;
  // A build's cost per ball over what a unit of skin adds to each ball's step (longer lists), in
  // units x steps: the skin that minimises their sum is sqrt(2 kSkinCostRatio x the drift per step).
  static constexpr float kSkinCostRatio = 70.0f;
};

// Everything the kernels need, derived once from PhysicsParams.
struct ContactModel {
  float k;
  float damping_factor;  // 2 zeta sqrt(k): c = damping_factor * sqrt(m_eff)
  float dt;
  float half_dt;
  float gravity;
  // No pair's overlap moves further than this in half a step: the fastest
  // ball's and the faster of that and a player's speed, times dt / 2. Pairs
  // further apart neither touch nor start to; the World sets it each step.
  float lead_bound = std::numeric_limits<float>::infinity();
};

float damping_ratio(float restitution);
float smallest_effective_mass();
float contact_duration(float stiffness);
float shortest_dt(float stiffness);  // t_c / kMaxStepsPerContact
// Why a dt below shortest_dt is refused: "is too short for k = ... (or 0 for automatic)".
std::string dt_too_short_text(float stiffness);
int steps_for_tolerance(float tolerance);
int steps_per_contact(const PhysicsParams& p);   // given, or from the tolerance
bool dt_from_tolerance(const PhysicsParams& p);  // neither dt nor steps per contact given
float derived_dt(const PhysicsParams& p);
inline float starting_skin(const PhysicsParams& p) { return p.skin > 0.0f ? p.skin : PhysicsParams::kStartSkin; }
// The softest k the tank's gravity allows: a column of the heaviest balls as
// tall as the tank presses its lowest contact in by less than the smallest
// radius. Softer piles sink balls through each other and the floor.
float softest_stiffness(const PhysicsParams& p);

// Empty when the parameters are usable; otherwise a message that says which
// value is wrong and what would be accepted.
std::string validate(const PhysicsParams& p);

// Requires validate(p) to be empty.
ContactModel make_contact_model(const PhysicsParams& p);

}  // namespace fishtank
