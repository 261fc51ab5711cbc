#pragma once
// Exact solutions of the contact model (docs/technical-report.md, section 2),
// in double precision: the answers the accuracy scenes are measured against.
//
// During a contact the overlap x of a pair (or of a ball and a wall) obeys
//   m x'' + c x' + k x = m a_push,   x(0) = 0,  x'(0) = v_in > 0,
// where a_push is a constant acceleration pressing the bodies together
// (gravity for a ball on the floor, 0 for a head-on collision). The contact
// ends when x returns to zero; the model has no clamp, so that is exact.

#include <vector>

namespace fishtank::accuracy {

struct LinearContact {
  double mass;  // effective mass of the pair (the ball's own mass against a wall)
  double k;     // stiffness, N/m
  double c;     // dashpot, N s/m
};

// Damping of a pair with effective mass m for restitution e (the product's rule).
double pair_damping(double k, double restitution, double mass);

struct ContactExit {
  bool ended;         // false if the bodies come to rest in contact
  double duration;    // s
  double exit_speed;  // separation speed when the overlap returns to zero
};

ContactExit exact_contact(const LinearContact& contact, double approach_speed, double push_accel);

// Velocities after a head-on collision along one axis with restitution e
// (exact for the linear model without external force).
struct Rebound {
  double v1, v2;
};
Rebound exact_rebound(double m1, double v1, double m2, double v2, double restitution);

// Apex heights (ball bottom above the floor) of the first `bounces` bounces of
// a ball of mass m dropped from rest at height h0, gravity g: free flight, then
// the damped oscillator with gravity for each contact.
std::vector<double> exact_apexes(const LinearContact& contact, double g, double h0, int bounces);

// The same apexes as if contacts were instantaneous: e^(2n) h0.
std::vector<double> instantaneous_apexes(double restitution, double h0, int bounces);

}  // namespace fishtank::accuracy
