#pragma once
// Multi-contact collisions, where no step can be exact: a ball hits a row of
// touching balls of diameter 1 on the x axis, a three-ball chain (two in the
// row) or a five-ball Newton's cradle (four). The reference integrates the
// same contact law in double with RK4 at t_c / 4000, each contact's onset and
// release located to round-off and stepped to, so its final velocities are
// good to about 1e-13; the World's error is its largest final velocity
// difference over the approach speed.

#include <vector>

#include "server/physics/kernels.h"

namespace fishtank::accuracy {

struct Row {
  int balls;  // in all, the moving one included
  double k, restitution, speed;
};

// Final velocities along x, in order along the row.
std::vector<double> reference_row(const Row& row);
std::vector<double> world_row(const Row& row, const Kernels& kernels, int steps_per_contact);
double row_error(const Row& row, const Kernels& kernels, int steps_per_contact);

}  // namespace fishtank::accuracy
