// Two facts of the contact law beyond single collisions (contact_law.h): a
// pile at rest stands on k x (in the dashpot's rate the spring and the other
// forces cancel), and an elastic gas keeps its energy.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "server/physics/world_measures.h"
#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

TEST_CASE("a settled pile's floor contacts carry its weight on k x, within 0.5 %", "[physics][rest]") {
  World world(PhysicsParams{}, kSseKernels, 1, 1);
  world.add_balls(1000);
  while (world.time() < 90.0 &&
         (world.pending() > 0 || world.time() < 10.0 || kinetic_energy(world) / world.ball_count() > 1e-5))
    world.step();
  REQUIRE(world.pending() == 0);
  double floor = 0.0, weight = 0.0;
  const float k = world.params().stiffness, g = world.params().gravity, bottom = world.params().tank.min.y;
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) {
    const Float4 p = world.positions()[i];
    if (p.y - p.w < bottom) floor += double(k) * (bottom + p.w - p.y);
    weight += double(kBallKinds[world.kinds()[i]].mass) * g;
  }
  INFO("floor force / weight " << floor / weight << " at " << world.time() << " s, kinetic energy per ball "
                               << kinetic_energy(world) / world.ball_count() << " J");
  CHECK(kinetic_energy(world) / world.ball_count() <= 1e-5);
  CHECK(floor / weight == Approx(1.0).margin(0.005));
}

// The gas's energy only wanders: a least-squares line through its 300 samples
// rises less than 1.5e-4 over them. While the window left the other contacts out
// (contact_law.h) every elastic collision of three balls gained energy and the
// line rose about 2.7e-4. E0 is read as the last ball is poured, when none
// touches; the 300 s start 20 s later, once the poured layer has struck the
// floor: while some 80 balls touch at once, k x^2 / 2 + m v^2 / 2 misreads the
// energy mid-contact by up to 2e-4, which recovers as they part. The scalar
// twin steps the same trajectory on every x86-64 processor (determinism_test.cpp),
// so the margins here are the same on every machine.
TEST_CASE("an elastic gas of 1000 balls keeps its energy over 300 s within 2e-4, with no upward drift",
          "[physics][energy]") {
  const int steps_per_contact = GENERATE(0, 20);
  PhysicsParams params;
  params.restitution = 1.0f;
  params.gravity = 0.0f;
  params.steps_per_contact = steps_per_contact;
  World world(params, kScalarKernels, 1, 7);
  world.add_balls(1000);
  while (world.pending() > 0) world.step();  // every ball poured in, moving at its spawn speed
  const auto energy = [&] { return kinetic_energy(world) + elastic_energy(world); };
  const double e0 = energy();
  constexpr int kSeconds = 300;
  double worst = 0.0, sum_t = 0.0, sum_e = 0.0, sum_tt = 0.0, sum_te = 0.0;
  const double start = world.time() + 20.0;
  for (int second = 1; second <= kSeconds; ++second) {
    while (world.time() < start + second) world.step();
    const double relative = (energy() - e0) / e0;
    worst = std::max(worst, std::fabs(relative));
    sum_t += second, sum_e += relative, sum_tt += double(second) * second, sum_te += second * relative;
  }
  const double rise = (kSeconds * sum_te - sum_t * sum_e) / (kSeconds * sum_tt - sum_t * sum_t) * kSeconds;
  INFO(steps_per_contact << " steps per contact (0: default): worst |E - E0| / E0 " << worst << ", the line rises "
                         << rise << " over " << kSeconds << " s");
  CHECK(worst <= 2e-4);
  CHECK(rise <= 1.5e-4);
}
