#pragma once
// Scenes with known answers (SPEC 7.1), each run by the product's World or by
// one of the 1-D schemes of contact_1d.h at a given dt, returning one error:
//
//   drop             ball (d = 1) dropped from about 1 unit onto the floor: worst error
//                    of the first three apex heights against exact_apexes, / h0, over
//                    kDropPhases heights (where in a step the first contact starts)
//   head-on          two balls meeting at 2 m/s, no gravity, every size pair: worst
//                    error of the rebound velocities against exact_rebound, / 2 m/s
//   head-on-elastic  the same with e = 1 (no dashpot)
//   energy           ball (d = 1) resting on the floor, e = 1, released 0.9 of its
//                    static overlap above equilibrium: worst energy error over five
//                    periods, / the oscillation energy
//
// An error is NaN when the run never produced the measured event (a contact
// that never ends, a bounce that never comes).

#include <vector>

#include "server/accuracy/contact_1d.h"
#include "server/physics/kernels.h"
#include "server/physics/params.h"

namespace fishtank::accuracy {

struct Method {
  const char* name;
  bool world;     // the product's World (float, full kernels) ...
  Scheme scheme;  // ... or this scheme on the 1-D problem (double)
};

// World first: it is what the product runs.
const std::vector<Method>& methods();

// The head-on scenes' balls start kHeadOnGap apart, each at a speed of SceneConfig::head_on_speed.
inline constexpr double kHeadOnSpeed = 1.0;
inline constexpr double kHeadOnGap = 0.05;

struct SceneConfig {
  double k = PhysicsParams{}.stiffness;  // the product's defaults
  double restitution = PhysicsParams{}.restitution;
  const Kernels* kernels = &kSseKernels;
  // The linear contact's restitution does not depend on it, but float32's floor, relative to the overlap, falls
  // as it rises: a faster head-on shows the scheme's order where the slow one meets the floor.
  double head_on_speed = kHeadOnSpeed;
};

struct Scene {
  const char* name;
  double (*error)(const Method& method, const SceneConfig& config, double dt);
};

const std::vector<Scene>& scenes();

// One size pair of the head-on scene (kinds index kBallKinds). The measured restitution is the rebound over
// the approach speed (NaN if the contact never ends).
// phase in [0, 1) shifts the start so the contact begins that far into a step.
double measured_restitution(const Method& method, const SceneConfig& config, double dt, int kind_a, int kind_b,
                            double phase = 0.0);
// The worst over kHeadOnPhases phases: one collision's error depends on where in a step it starts.
double head_on_pair_error(const Method& method, const SceneConfig& config, double dt, int kind_a, int kind_b);
inline constexpr int kHeadOnPhases = 8;

// The drop scene's constants and the apexes a run measures.
inline constexpr double kDropHeight = 1.0;
inline constexpr int kDropBounces = 3;
inline constexpr int kDropPhases = 8;  // heights the drop's error is the worst of
std::vector<double> measured_apexes(const Method& method, const SceneConfig& config, double dt,
                                    double height = kDropHeight);

}  // namespace fishtank::accuracy
