#include "server/accuracy/sweep.h"

#include <cmath>
#include <ctime>
#include <limits>

#include "server/physics/params.h"

namespace fishtank::accuracy {
namespace {

double cpu_now() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

}  // namespace

std::vector<SweepPoint> run_sweep(const SceneConfig& config, const std::vector<int>& steps_per_contact,
                                  double min_cpu_seconds) {
  const double t_c = contact_duration(static_cast<float>(config.k));
  std::vector<SweepPoint> points;
  for (const Scene& scene : scenes())
    for (const Method& method : methods())
      for (int n : steps_per_contact) {
        const double dt = t_c / n;
        // Short runs are repeated so the clock's granularity does not dominate.
        const double start = cpu_now();
        double error = scene.error(method, config, dt);
        int runs = 1;
        while (cpu_now() - start < min_cpu_seconds) {
          scene.error(method, config, dt);
          ++runs;
        }
        points.push_back({scene.name, method.name, n, dt, error, (cpu_now() - start) / runs});
      }
  return points;
}

double log_log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int count = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!(x[i] > 0.0 && y[i] > 0.0 && std::isfinite(x[i]) && std::isfinite(y[i]))) continue;
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
    ++count;
  }
  if (count < 2) return std::numeric_limits<double>::quiet_NaN();
  return (count * sxy - sx * sy) / (count * sxx - sx * sx);
}

std::vector<Order> fit_orders(const std::vector<SweepPoint>& points, int min_steps, int max_steps) {
  std::vector<Order> orders;
  for (const Scene& scene : scenes())
    for (const Method& method : methods()) {
      std::vector<double> dt, cpu, error;
      for (const SweepPoint& p : points)
        if (p.scene == scene.name && p.method == method.name && p.steps_per_contact >= min_steps &&
            p.steps_per_contact <= max_steps) {
          dt.push_back(p.dt);
          cpu.push_back(p.cpu_seconds);
          error.push_back(p.error);
        }
      orders.push_back({scene.name, method.name, log_log_slope(dt, error), log_log_slope(cpu, error)});
    }
  return orders;
}

}  // namespace fishtank::accuracy
