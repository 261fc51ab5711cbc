#include "server/physics/params.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace fishtank {

namespace {
constexpr float kPi = 3.14159265358979f;
// Softer, even without gravity, a contact lasts over 2.2 s: steps too far apart to watch.
constexpr float kSoftestStiffness = 1.0f;
// The floors the refusals print (six digits, so up to 5e-6 low) are accepted as typed back.
constexpr float kPrintedSlack = 1e-5f;
}  // namespace

float damping_ratio(float restitution) {
  float ln_e = std::log(restitution);
  return -ln_e / std::sqrt(kPi * kPi + ln_e * ln_e);
}

float smallest_effective_mass() {
  float lightest = kBallKinds[0].mass;
  for (const BallKind& kind : kBallKinds) lightest = std::min(lightest, kind.mass);
  return lightest * lightest / (lightest + lightest);
}

float contact_duration(float stiffness) { return kPi * std::sqrt(smallest_effective_mass() / stiffness); }

float softest_stiffness(const PhysicsParams& p) {
  const BallKind& heaviest =
      *std::max_element(kBallKinds.begin(), kBallKinds.end(), [](auto& a, auto& b) { return a.mass < b.mass; });
  const float column_weight = p.tank.size().y / heaviest.diameter * heaviest.mass * std::fabs(p.gravity);
  return column_weight / (0.5f * kMinBallDiameter);
}

float shortest_dt(float stiffness) { return contact_duration(stiffness) / PhysicsParams::kMaxStepsPerContact; }

std::string dt_too_short_text(float stiffness) {
  std::ostringstream text;
  text << "is too short for k = " << stiffness << " N/m: at most " << PhysicsParams::kMaxStepsPerContact
       << " steps per contact, so dt must be >= " << shortest_dt(stiffness) << " s (or 0 for automatic)";
  return text.str();
}

int steps_for_tolerance(float tolerance) {
  return static_cast<int>(std::ceil(std::sqrt(PhysicsParams::kToleranceRule / tolerance) - 1e-4f));
}

int steps_per_contact(const PhysicsParams& p) {
  return p.steps_per_contact > 0 ? p.steps_per_contact : steps_for_tolerance(p.tolerance);
}

bool dt_from_tolerance(const PhysicsParams& p) { return p.dt <= 0.0f && p.steps_per_contact <= 0; }

float derived_dt(const PhysicsParams& p) {
  return p.dt > 0.0f ? p.dt : contact_duration(p.stiffness) / static_cast<float>(steps_per_contact(p));
}

std::string validate(const PhysicsParams& p) {
  std::ostringstream err;
  // The range stated is this gravity's and tank's (the softest check below), where those are valid numbers.
  const float softest =
      std::isfinite(softest_stiffness(p)) ? std::max(kSoftestStiffness, softest_stiffness(p)) : kSoftestStiffness;
  if (!std::isfinite(p.stiffness) || p.stiffness < kSoftestStiffness || p.stiffness > 1.0e9f)
    err << "stiffness k must be in [" << softest << ", 1e9] N/m, got " << p.stiffness;
  else if (!std::isfinite(p.restitution) || p.restitution <= 0.0f || p.restitution > 1.0f)
    err << "restitution e must be in (0, 1], got " << p.restitution;
  else if (!std::isfinite(p.tolerance) || p.tolerance < PhysicsParams::kTightestTolerance ||
           p.tolerance > PhysicsParams::kLoosestTolerance)
    err << "tolerance must be in [" << PhysicsParams::kTightestTolerance << ", " << PhysicsParams::kLoosestTolerance
        << "], got " << p.tolerance << ": a looser one needs fewer than " << PhysicsParams::kMinStepsPerContact
        << " steps per contact, which is unstable; below " << PhysicsParams::kTightestTolerance
        << " float32 positions cannot resolve a slow contact (use --steps-per-contact for more steps)";
  else if (p.steps_per_contact != 0 && (p.steps_per_contact < PhysicsParams::kMinStepsPerContact ||
                                        p.steps_per_contact > PhysicsParams::kMaxStepsPerContact))
    err << "steps per contact must be in [" << PhysicsParams::kMinStepsPerContact << ", "
        << PhysicsParams::kMaxStepsPerContact << "], got " << p.steps_per_contact;
  else if (!std::isfinite(p.dt) || p.dt < 0.0f)
    err << "dt must be a positive number of seconds (or 0 for automatic), got " << p.dt;
  else if (p.dt > contact_duration(p.stiffness) / PhysicsParams::kMinStepsPerContact)
    err << "dt = " << p.dt << " s is unstable for k = " << p.stiffness
        << " N/m: a contact lasts t_c = " << contact_duration(p.stiffness) << " s and needs at least "
        << PhysicsParams::kMinStepsPerContact
        << " steps, so dt must be <= " << contact_duration(p.stiffness) / PhysicsParams::kMinStepsPerContact
        << " s (automatic: " << contact_duration(p.stiffness) / static_cast<float>(steps_per_contact(p)) << " s)";
  else if (p.dt > 0.0f && p.dt < shortest_dt(p.stiffness) * (1.0f - kPrintedSlack))
    err << "dt = " << p.dt << " s " << dt_too_short_text(p.stiffness);
  else if (!std::isfinite(p.skin) || p.skin < 0.0f || p.skin > 10.0f)
    err << "neighbour skin must be in (0, 10] units, or 0 to follow the motion, got " << p.skin;
  else if (!std::isfinite(p.gravity) || std::fabs(p.gravity) > 1000.0f)
    err << "gravity must be in [-1000, 1000] m/s^2, got " << p.gravity;
  else if (!std::isfinite(p.player_max_speed) || p.player_max_speed < 0.0f || p.player_max_speed > 100.0f)
    err << "player max speed must be in [0, 100] m/s, got " << p.player_max_speed;
  else {
    Vec3 s = p.tank.size();
    if (!is_finite(s) || s.x < 4.0f || s.y < 4.0f || s.z < 4.0f || s.x > 1.0e5f || s.z > 1.0e5f || s.y > 1.0e5f)
      err << "tank must be between 4 and 1e5 units on each side";
    else if (p.stiffness < softest_stiffness(p) * (1.0f - kPrintedSlack))
      err << "stiffness k = " << p.stiffness << " N/m is too soft for gravity " << p.gravity << " m/s^2 in a tank "
          << s.y << " high: a pile that fills it would press balls through each other and the floor; k must be at "
          << "least " << softest_stiffness(p) << " N/m (the default is " << PhysicsParams{}.stiffness << ")";
  }
  return err.str();
}

ContactModel make_contact_model(const PhysicsParams& p) {
  ContactModel m;
  m.k = p.stiffness;
  m.damping_factor = 2.0f * damping_ratio(p.restitution) * std::sqrt(p.stiffness);
  m.dt = derived_dt(p);
  m.half_dt = 0.5f * m.dt;
  m.gravity = p.gravity;
  return m;
}

}  // namespace fishtank
