#include "server/accuracy/rows.h"

#include <algorithm>
#include <cmath>

#include "server/accuracy/reference.h"
#include "server/physics/params.h"
#include "server/physics/world.h"

namespace fishtank::accuracy {
namespace {

constexpr double kGap = 0.05;  // between the moving ball and the row
constexpr int kKind = 0;       // diameter 1, mass 1

// Simulated seconds until every contact of the row is over: the approach, then a few contacts per ball.
double duration(const Row& row) {
  return kGap / row.speed + 4.0 * row.balls * contact_duration(static_cast<float>(row.k));
}

double start_x(int b) { return b == 0 ? -1.0 - kGap : double(b - 1); }

}  // namespace

std::vector<double> reference_row(const Row& row) {
  const int n = row.balls;
  const double m = kBallKinds[kKind].mass, reach = kBallKinds[kKind].diameter;
  const double c = pair_damping(row.k, row.restitution, 0.5 * m);  // two equal balls: m_eff = m / 2
  std::vector<double> x(n), v(n, 0.0);
  for (int b = 0; b < n; ++b) x[b] = start_x(b);
  v[0] = row.speed;
  // dx/dt = v, dv/dt = a(x, v): the law of report 2.2 between neighbours, no clamp.
  const auto accel = [&](const std::vector<double>& px, const std::vector<double>& pv, std::vector<double>& a) {
    std::fill(a.begin(), a.end(), 0.0);
    for (int b = 0; b + 1 < n; ++b) {
      const double overlap = reach - (px[b + 1] - px[b]);
      if (overlap <= 0.0) continue;
      const double f = row.k * overlap + c * (pv[b] - pv[b + 1]);
      a[b] -= f / m;
      a[b + 1] += f / m;
    }
  };
  const double dt = contact_duration(static_cast<float>(row.k)) / 40000.0;
  std::vector<double> k1x(n), k1v(n), k2x(n), k2v(n), k3x(n), k3v(n), k4x(n), k4v(n), tx(n), tv(n);
  for (double t = 0.0; t < duration(row); t += dt) {
    const auto stage = [&](const std::vector<double>& dx, const std::vector<double>& dv, double h,
                           std::vector<double>& ox, std::vector<double>& ov) {
      for (int b = 0; b < n; ++b) tx[b] = x[b] + h * dx[b], tv[b] = v[b] + h * dv[b];
      ox = tv;
      accel(tx, tv, ov);
    };
    k1x = v;
    accel(x, v, k1v);
    stage(k1x, k1v, 0.5 * dt, k2x, k2v);
    stage(k2x, k2v, 0.5 * dt, k3x, k3v);
    stage(k3x, k3v, dt, k4x, k4v);
    for (int b = 0; b < n; ++b) {
      x[b] += dt / 6.0 * (k1x[b] + 2.0 * k2x[b] + 2.0 * k3x[b] + k4x[b]);
      v[b] += dt / 6.0 * (k1v[b] + 2.0 * k2v[b] + 2.0 * k3v[b] + k4v[b]);
    }
  }
  return v;
}

std::vector<double> world_row(const Row& row, const Kernels& kernels, int steps_per_contact) {
  PhysicsParams params;
  params.gravity = 0.0f;
  params.stiffness = static_cast<float>(row.k);
  params.restitution = static_cast<float>(row.restitution);
  params.steps_per_contact = steps_per_contact;
  params.tank.min = {-10.0f, -10.0f, -10.0f};
  params.tank.max = {10.0f, 10.0f, 10.0f};
  World world(params, kernels, 1, 1);
  for (int b = 0; b < row.balls; ++b)
    world.place_ball(kKind, {static_cast<float>(start_x(b)), 0.0f, 0.0f},
                     {b == 0 ? static_cast<float>(row.speed) : 0.0f, 0.0f, 0.0f});
  while (world.time() < duration(row)) world.step();
  // Placed balls keep their order of placement.
  std::vector<double> v(row.balls);
  for (int b = 0; b < row.balls; ++b) v[b] = world.ball(b).vel.x;
  return v;
}

double row_error(const Row& row, const Kernels& kernels, int steps_per_contact) {
  const std::vector<double> exact = reference_row(row), world = world_row(row, kernels, steps_per_contact);
  double worst = 0.0;
  for (int b = 0; b < row.balls; ++b) worst = std::max(worst, std::fabs(world[b] - exact[b]) / row.speed);
  return worst;
}

}  // namespace fishtank::accuracy
