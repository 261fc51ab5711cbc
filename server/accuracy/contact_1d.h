#pragma once
// The scenes' contacts reduced to one coordinate, integrated in double by the
// schemes the product could have used. A head-on pair reduces exactly to one
// body of the effective mass (equal and opposite forces), a ball on the floor
// is one body of its own mass, so every scheme solves the same problem as the
// product's World.
//
//   x  overlap (positive in contact, minus the gap in flight)
//   u  dx/dt
//   force along x: -k x - c u while x > 0, plus m a_push (gravity on the floor)

#include "server/accuracy/reference.h"

namespace fishtank::accuracy {

enum class Scheme {
  kVerlet,           // LAMMPS-like velocity Verlet, dashpot on the half-step velocity (the product replaced it)
  kSymplecticEuler,  // u += a(x, u) dt, then x += u dt
  kExplicitEuler,    // x and u both advanced with the old state
};

struct State1D {
  double x, u;
  double a;  // acceleration at (x, u); Verlet's first half kick needs it
};

class Contact1D {
 public:
  Contact1D(const LinearContact& contact, double push_accel, Scheme scheme, double dt, double x0, double u0);

  void step();
  const State1D& state() const { return s_; }

 private:
  double accel(double x, double u) const;

  LinearContact contact_;
  double push_;
  Scheme scheme_;
  double dt_;
  State1D s_;
};

}  // namespace fishtank::accuracy
