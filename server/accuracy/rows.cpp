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
// RK4 steps per contact in the reference: its error is then below round-off (~1e-14 here); more only
// adds round-off.
constexpr double kReferenceSteps = 4000.0;

// Simulated seconds until every contact of the row is over: the approach, then a few contacts per ball.
double duration(const Row& row) {
  return kGap / row.speed + 4.0 * row.balls * contact_duration(static_cast<float>(row.k));
}

double start_x(int b) { return b == 0 ? -1.0 - kGap : double(b - 1); }

// RK4 with each contact's state (in or out) held over a step, so the law is linear and smooth within
// it; a step in which an overlap changes sign is cut at the crossing, found by bisection on its
// length, and that contact's state flips there. A fixed step would instead smear the dashpot's jump
// at every onset and release over one step: an O(h) error in the final velocities.
std::vector<double> integrate_row(const Row& row, double steps_per_contact) {
  const int n = row.balls;
  const double m = kBallKinds[kKind].mass, reach = kBallKinds[kKind].diameter;
  const double c = pair_damping(row.k, row.restitution, 0.5 * m);  // two equal balls: m_eff = m / 2
  // Displacements from the start: the touching pairs' overlaps are then exactly 0 until they move,
  // not the round-off of 1 - (x[b+1] - x[b]).
  std::vector<double> rest(n - 1);
  for (int b = 0; b + 1 < n; ++b) rest[b] = reach - (start_x(b + 1) - start_x(b));
  struct State {
    std::vector<double> u, v;
  };
  State s{std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)}, next = s;
  s.v[0] = row.speed;
  std::vector<char> in(n - 1, 0);
  const auto overlap = [&](const std::vector<double>& u, int b) { return rest[b] + u[b] - u[b + 1]; };
  // dv/dt: the law of report 2.2 between neighbours, no clamp, for the contacts marked in.
  const auto accel = [&](const std::vector<double>& u, const std::vector<double>& v, std::vector<double>& a) {
    std::fill(a.begin(), a.end(), 0.0);
    for (int b = 0; b + 1 < n; ++b) {
      if (!in[b]) continue;
      const double f = row.k * overlap(u, b) + c * (v[b] - v[b + 1]);
      a[b] -= f / m;
      a[b + 1] += f / m;
    }
  };
  std::vector<double> k1v(n), k2v(n), k3v(n), k4v(n), k2u(n), k3u(n), k4u(n), tu(n);
  const auto rk4 = [&](const State& q, double h, State& out) {
    accel(q.u, q.v, k1v);
    for (int b = 0; b < n; ++b) tu[b] = q.u[b] + 0.5 * h * q.v[b], k2u[b] = q.v[b] + 0.5 * h * k1v[b];
    accel(tu, k2u, k2v);
    for (int b = 0; b < n; ++b) tu[b] = q.u[b] + 0.5 * h * k2u[b], k3u[b] = q.v[b] + 0.5 * h * k2v[b];
    accel(tu, k3u, k3v);
    for (int b = 0; b < n; ++b) tu[b] = q.u[b] + h * k3u[b], k4u[b] = q.v[b] + h * k3v[b];
    accel(tu, k4u, k4v);
    for (int b = 0; b < n; ++b) {
      out.u[b] = q.u[b] + h / 6.0 * (q.v[b] + 2.0 * k2u[b] + 2.0 * k3u[b] + k4u[b]);
      out.v[b] = q.v[b] + h / 6.0 * (k1v[b] + 2.0 * k2v[b] + 2.0 * k3v[b] + k4v[b]);
    }
  };
  const auto crossed = [&](const State& q) {
    for (int b = 0; b + 1 < n; ++b)
      if ((overlap(q.u, b) > 0.0) != static_cast<bool>(in[b])) return true;
    return false;
  };
  const double dt = contact_duration(static_cast<float>(row.k)) / steps_per_contact, end = duration(row);
  for (double t = 0.0; t < end;) {
    double h = std::min(dt, end - t);
    rk4(s, h, next);
    if (crossed(next)) {
      // The first crossing to 2^-64 of the step (a contact lasts t_c at any speed, so no overlap
      // crosses twice in one): the dashpot's jump then lands within round-off of its time. The step
      // is taken to just past it, where the crossed overlaps have their new sign.
      double lo = 0.0;
      for (int i = 0; i < 64; ++i) {
        const double mid = 0.5 * (lo + h);
        rk4(s, mid, next);
        if (crossed(next))
          h = mid;
        else
          lo = mid;
      }
      rk4(s, h, next);
      for (int b = 0; b + 1 < n; ++b) in[b] = overlap(next.u, b) > 0.0;
    }
    std::swap(s, next);
    t += h;
  }
  return s.v;
}

}  // namespace

std::vector<double> reference_row(const Row& row) { return integrate_row(row, kReferenceSteps); }

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
