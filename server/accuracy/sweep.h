#pragma once
// The dt sweep of SPEC 7.1: every scene by every method at dt = t_c / n, with
// the error and the CPU time of one run, and the observed orders fitted to it.

#include <string>
#include <vector>

#include "server/accuracy/scenes.h"

namespace fishtank::accuracy {

struct SweepPoint {
  std::string scene, method;
  int steps_per_contact;  // n in dt = t_c / n, t_c the product's (lightest pair)
  double dt;
  double error;
  double cpu_seconds;  // one run, averaged over as many as min_cpu_seconds took
};

std::vector<SweepPoint> run_sweep(const SceneConfig& config, const std::vector<int>& steps_per_contact,
                                  double min_cpu_seconds);

// Least-squares slope of log y against log x over the points where both are
// finite and positive; NaN with fewer than two.
double log_log_slope(const std::vector<double>& x, const std::vector<double>& y);

struct Order {
  std::string scene, method;
  double vs_dt;   // p in error ~ dt^p
  double vs_cpu;  // q in error ~ cpu^q (-p when the cost is 1/dt)
};

// Orders fitted over the points with min_steps <= n <= max_steps.
std::vector<Order> fit_orders(const std::vector<SweepPoint>& points, int min_steps, int max_steps);

}  // namespace fishtank::accuracy
