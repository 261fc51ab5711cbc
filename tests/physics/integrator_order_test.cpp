// Velocity Verlet is second order: on an undamped contact with a known
// solution, the error falls about fourfold each time dt halves.

#include <catch2/catch.hpp>
#include <cmath>

#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

namespace {

// A unit ball resting on the floor, started above its equilibrium so it
// oscillates without ever leaving the floor: y(t) = y_eq + A cos(w t). The
// floor sits at y = -0.5 so the centre stays near 0, where float spacing is
// far below the errors being measured.
double oscillation_error(const Kernels& kernels, float dt, float duration) {
  PhysicsParams p;
  p.restitution = 1.0f;  // no damping
  p.tank.min = {-5.0f, -0.5f, -5.0f};
  p.tank.max = {5.0f, 9.5f, 5.0f};
  p.dt = dt;
  World world(p, kernels, 1, 1);
  const float g = p.gravity, k = p.stiffness, m = kBallKinds[0].mass;
  const double y_eq = -m * g / k;  // centre of a 0.5 ball squeezed by its weight
  const double amplitude = 0.5 * m * g / k;
  world.place_ball(0, {0.0f, static_cast<float>(y_eq + amplitude), 0.0f}, {0.0f, 0.0f, 0.0f});
  const int steps = static_cast<int>(std::lround(duration / dt));
  for (int s = 0; s < steps; ++s) world.step();
  const double omega = std::sqrt(k / m);
  const double exact = y_eq + amplitude * std::cos(omega * steps * double(dt));
  return std::fabs(world.ball(0).pos.y - exact);
}

}  // namespace

TEST_CASE("velocity Verlet error falls ~4x when dt halves (second order)", "[physics][convergence]") {
  const Kernels& kernels = kernels_named(GENERATE(from_range(variant_names())));
  const float duration = 0.1f;         // a little over two periods
  const float dt = duration / 200.0f;  // 0.5 ms, below the default 0.79 ms
  const double e1 = oscillation_error(kernels, dt, duration);
  const double e2 = oscillation_error(kernels, dt / 2, duration);
  const double e4 = oscillation_error(kernels, dt / 4, duration);
  INFO(kernels.variant << ": errors " << e1 << ", " << e2 << ", " << e4);
  CHECK(e1 / e2 == Approx(4.0).margin(0.5));
  CHECK(e2 / e4 == Approx(4.0).margin(0.5));
}
