// Every single collision rebounds with the contact model's restitution, not
// only on average: e from 0.05 to 1, every size pair, walls and the player,
// approach speeds from 0.1 to 20 m/s, and the contact starting anywhere
// within a step. Without gravity the model's exact answer (overlap-ends
// definition, no clamp at zero force; report 2.2) is e itself.

#include <catch2/catch.hpp>

#include "server/accuracy/collisions.h"
#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::accuracy;
using namespace fishtank::test;

TEST_CASE("every collision at the default settings is within 0.005 of the model's e, in every variant",
          "[physics][restitution][sweep]") {
  const std::string variant = GENERATE(from_range(variant_names()));
  const float e = GENERATE(from_range(kSweepRestitutions));
  PhysicsParams params = open_space();
  params.restitution = e;
  const CollisionErrors errors =
      sweep_collisions(kernels_named(variant), params, every_collision(kSweepSpeeds, kSweepPhases));
  INFO(variant << " e = " << e << ": " << errors.within_5e3 << " of " << errors.collisions << " within 0.005, worst "
               << errors.worst << " (" << errors.worst_case << ")");
  CHECK(errors.collisions == 12 * 4 * 20);
  // What the status line states, in every variant the servers ship (#41 asked 95 % within it, all within 0.01).
  CHECK(errors.worst <= params.tolerance);
}

TEST_CASE("each tolerance meets itself: every collision at the steps it sets is within it",
          "[physics][restitution][sweep]") {
  const float tolerance =
      GENERATE(0.0075f, 0.005f, 0.003f, 0.002f);  // the loosest and the tightest accepted among them
  PhysicsParams params = open_space();
  params.tolerance = tolerance;
  for (float e : kSweepRestitutions) {
    params.restitution = e;
    const CollisionErrors errors = sweep_collisions(kSseKernels, params, every_collision(kSweepSpeeds, kSweepPhases));
    INFO("tolerance " << tolerance << " (" << steps_per_contact(params) << " steps per contact), e = " << e
                      << ": worst " << errors.worst << " (" << errors.worst_case << ")");
    CHECK(errors.worst <= tolerance);
  }
}
