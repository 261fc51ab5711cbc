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

TEST_CASE("automatic dt resolves the shortest contact in the tolerance's steps, or in those given", "[params]") {
  PhysicsParams p;
  const float t_c = 3.14159265f * std::sqrt(0.5f / p.stiffness);  // two unit masses: m_eff = 0.5
  CHECK(contact_duration(p.stiffness) == Approx(t_c));
  // The default tolerance 0.005: ceil(sqrt(0.8 / 0.005)) = 13 steps; t_c = 14.05 ms, 925 steps per second.
  CHECK(steps_per_contact(p) == 13);
  CHECK(derived_dt(p) == Approx(t_c / 13));
  CHECK(1.0f / derived_dt(p) == Approx(925.3f).epsilon(0.01));
  p.steps_per_contact = 20;
  CHECK(derived_dt(p) == Approx(t_c / 20));
}

TEST_CASE("a tighter tolerance takes more steps per contact, the rule at its ends", "[params]") {
  CHECK(steps_for_tolerance(PhysicsParams::kLoosestTolerance) == 11);
  CHECK(steps_for_tolerance(0.001f) == 29);
  CHECK(steps_for_tolerance(PhysicsParams::kTightestTolerance) == 20);
}

TEST_CASE("defaults are valid", "[params]") { CHECK(validate(PhysicsParams{}).empty()); }

TEST_CASE("unstable or absurd parameters are refused with a reason", "[params]") {
  PhysicsParams p;
  SECTION("dt too long for the stiffness") {
    p.dt = contact_duration(p.stiffness) / 5.0f;
    CHECK(validate(p).find("unstable") != std::string::npos);
  }
  SECTION("stiffness too soft for a pile under gravity, and the least allowed is accepted") {
    // A column of 3 kg balls 40 high weighs 13.3 x 3 x 9.81 N: under 0.5 in, k >= 784.8 N/m.
    CHECK(softest_stiffness(p) == Approx(40.0 / 3.0 * 3.0 * 9.81 / 0.5));
    p.stiffness = 0.99f * softest_stiffness(p);
    const std::string why = validate(p);
    CHECK(why.find("too soft") != std::string::npos);
    CHECK(why.find("at least 784.8 N/m") != std::string::npos);
    p.stiffness = softest_stiffness(p);
    CHECK(validate(p).empty());
    p.stiffness = 784.8f;  // the floor as the message and --help print it
    CHECK(validate(p).empty());
  }
  SECTION("stiffness below 1 N/m, even without gravity") {
    p.gravity = 0.0f;
    p.stiffness = 0.5f;
    CHECK(validate(p).find("stiffness k must be in [1, 1e9]") != std::string::npos);
  }
  SECTION("stiffness below 1 N/m under gravity: the range stated is gravity's") {
    p.stiffness = 0.5f;
    CHECK(validate(p).find("stiffness k must be in [784.8, 1e9]") != std::string::npos);
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
  SECTION("a tolerance too loose for a stable step") {
    p.tolerance = 0.01f;
    CHECK(validate(p).find("unstable") != std::string::npos);
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
