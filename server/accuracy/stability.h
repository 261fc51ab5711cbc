#pragma once
// The stability map of SPEC 7.2: for a stiffness k and a time step dt, run two
// small stiff scenes with the product's World and classify the pair.
//
//   pile       36 light balls (d = 1, the pair that sets t_c) dropped as a loose
//              3 x 4 x 3 lattice into a 4 x 10 x 4 box, run for kPileSeconds
//   collision  two light balls head-on at 2 m/s, no gravity: the restitution
//
//   unstable     a non-finite ball or one lost from the tank, kinetic + gravitational energy
//                above kBlowUp times the start (damping only removes energy),
//                or a collision that creates energy (e > 1) or never ends
//   inaccurate   restitution off by more than kRestitutionTolerance (relative),
//                or a pile overlap above kOverlapTolerance of the radius
//   accurate     otherwise

#include "server/physics/kernels.h"

namespace fishtank::accuracy {

enum class Stability { kUnstable = 0, kInaccurate = 1, kAccurate = 2 };
const char* stability_name(Stability s);

inline constexpr double kPileSeconds = 1.0;
inline constexpr double kBlowUp = 1.5;
inline constexpr double kRestitutionTolerance = 0.05;
inline constexpr double kOverlapTolerance = 0.10;

struct StabilityCell {
  double k, dt;
  double restitution;   // measured, for e = 0.6
  double overlap;       // largest in the pile at the end, fraction of the smaller radius
  double energy_ratio;  // largest (kinetic + gravitational) / start seen in the pile
  Stability stability;
};

StabilityCell classify(double k, double dt, const Kernels& kernels);

}  // namespace fishtank::accuracy
