#include "server/accuracy/contact_1d.h"

namespace fishtank::accuracy {

Contact1D::Contact1D(const LinearContact& contact, double push_accel, Scheme scheme, double dt, double x0, double u0)
    : contact_(contact), push_(push_accel), scheme_(scheme), dt_(dt), s_{x0, u0, 0.0} {
  s_.a = accel(x0, u0);
}

double Contact1D::accel(double x, double u) const {
  const double force = x > 0.0 ? -contact_.k * x - contact_.c * u : 0.0;
  return force / contact_.mass + push_;
}

void Contact1D::step() {
  switch (scheme_) {
    case Scheme::kVerlet: {
      // As the kernels do: the dashpot sees the half-step velocity.
      const double u_half = s_.u + 0.5 * dt_ * s_.a;
      s_.x += u_half * dt_;
      s_.a = accel(s_.x, u_half);
      s_.u = u_half + 0.5 * dt_ * s_.a;
      break;
    }
    case Scheme::kSymplecticEuler:
      s_.u += accel(s_.x, s_.u) * dt_;
      s_.x += s_.u * dt_;
      break;
    case Scheme::kExplicitEuler: {
      const double a = accel(s_.x, s_.u);
      s_.x += s_.u * dt_;
      s_.u += a * dt_;
      break;
    }
  }
}

}  // namespace fishtank::accuracy
