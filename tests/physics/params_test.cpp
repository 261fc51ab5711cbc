// The derivation of damping and time step from e and k, and the refusal of
// parameters that would make the integration unstable or meaningless.

#include "server/physics/params.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

using namespace fishtank;

TEST_CASE("damping ratio follows zeta = -ln e / sqrt(pi^2 + ln^2 e)", "[params]") {
  CHECK(damping_ratio(0.6f) == Approx(0.16048).epsilon(1e-3));
  CHECK(damping_ratio(1.0f) == Approx(0.0).margin(1e-7));
  // Lower restitution needs more damping.
  CHECK(damping_ratio(0.1f) > damping_ratio(0.6f));
}

TEST_CASE("automatic dt resolves the shortest contact in steps_per_contact steps", "[params]") {
  PhysicsParams p;
  const float t_c = 3.14159265f * std::sqrt(0.5f / p.stiffness);  // two unit masses: m_eff = 0.5
  CHECK(contact_duration(p.stiffness) == Approx(t_c));
  CHECK(derived_dt(p) == Approx(t_c / p.steps_per_contact));
  // The default k = 2.5e4 N/m: t_c = 14.05 ms, about 1420 steps per simulated second.
  CHECK(1.0f / derived_dt(p) == Approx(1423.5f).epsilon(0.01));
}

TEST_CASE("defaults are valid", "[params]") { CHECK(validate(PhysicsParams{}).empty()); }

TEST_CASE("unstable or absurd parameters are refused with a reason", "[params]") {
  PhysicsParams p;
  SECTION("dt too long for the stiffness") {
    p.dt = contact_duration(p.stiffness) / 5.0f;
    CHECK(validate(p).find("unstable") != std::string::npos);
  }
  SECTION("stiffness NaN") {
    p.stiffness = std::numeric_limits<float>::quiet_NaN();
    CHECK(validate(p).find("stiffness") != std::string::npos);
  }
  SECTION("restitution zero") {
    p.restitution = 0.0f;
    CHECK(validate(p).find("restitution") != std::string::npos);
  }
  SECTION("restitution above one") {
    p.restitution = 1.5f;
    CHECK(validate(p).find("restitution") != std::string::npos);
  }
  SECTION("negative dt") {
    p.dt = -1.0f;
    CHECK(validate(p).find("dt") != std::string::npos);
  }
  SECTION("too few steps per contact") {
    p.steps_per_contact = 3;
    CHECK(validate(p).find("steps per contact") != std::string::npos);
  }
  SECTION("degenerate tank") {
    p.tank.max.x = p.tank.min.x;
    CHECK(validate(p).find("tank") != std::string::npos);
  }
}
