#include "server/accuracy/reference.h"

#include <cmath>

namespace fishtank::accuracy {

double pair_damping(double k, double restitution, double mass) {
  const double ln_e = std::log(restitution);
  const double zeta = -ln_e / std::sqrt(M_PI * M_PI + ln_e * ln_e);
  return 2.0 * zeta * std::sqrt(k * mass);
}

ContactExit exact_contact(const LinearContact& contact, double approach_speed, double push_accel) {
  // x(t) = x_eq + exp(-s t) (A cos(w t) + B sin(w t)), underdamped because e > 0.
  const double w0_sq = contact.k / contact.mass;
  const double s = contact.c / (2.0 * contact.mass);
  const double w = std::sqrt(w0_sq - s * s);
  const double x_eq = push_accel / w0_sq;
  const double a = -x_eq;
  const double b = (approach_speed + s * a) / w;
  auto overlap = [&](double t) { return x_eq + std::exp(-s * t) * (a * std::cos(w * t) + b * std::sin(w * t)); };
  auto rate = [&](double t) {
    return std::exp(-s * t) * ((-s * a + w * b) * std::cos(w * t) + (-s * b - w * a) * std::sin(w * t));
  };

  // The first zero lies within the first period; scan finely enough that no
  // sign change is skipped, then bisect to double precision.
  const double half_period = M_PI / w;
  const double scan = half_period / 256.0;
  double lo = scan;
  for (double hi = 2.0 * scan; hi <= 4.0 * half_period; lo = hi, hi += scan) {
    if (overlap(hi) > 0.0) continue;
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      (overlap(mid) > 0.0 ? lo : hi) = mid;
    }
    return {true, hi, -rate(hi)};
  }
  return {false, 0.0, 0.0};
}

Rebound exact_rebound(double m1, double v1, double m2, double v2, double restitution) {
  const double approach = v1 - v2;
  const double total = m1 + m2;
  return {v1 - (1.0 + restitution) * m2 / total * approach, v2 + (1.0 + restitution) * m1 / total * approach};
}

std::vector<double> exact_apexes(const LinearContact& contact, double g, double h0, int bounces) {
  std::vector<double> apexes;
  double h = h0;
  for (int n = 0; n < bounces; ++n) {
    // Free flight is symmetric: the ball meets the floor at the speed it left it.
    const ContactExit exit = exact_contact(contact, std::sqrt(2.0 * g * h), g);
    if (!exit.ended) break;
    h = exit.exit_speed * exit.exit_speed / (2.0 * g);
    apexes.push_back(h);
  }
  return apexes;
}

std::vector<double> instantaneous_apexes(double restitution, double h0, int bounces) {
  std::vector<double> apexes;
  for (int n = 1; n <= bounces; ++n) apexes.push_back(std::pow(restitution, 2 * n) * h0);
  return apexes;
}

}  // namespace fishtank::accuracy
