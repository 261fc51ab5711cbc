#pragma once
// What observers measure of a world (status lines, the benchmark's report,
// tests): free functions over its state, which the step never calls.

#include <cstdint>
#include <string>
#include <vector>

#include "common/float4.h"
#include "server/physics/world.h"

namespace fishtank {

// A ball's kinetic plus gravitational energy (vel's w is the mass), relative to y = 0.
double ball_energy(const Float4& pos, const Float4& vel, float gravity);

double kinetic_energy(const World& world);
float max_speed(const World& world);          // the fastest ball's, m/s
double potential_energy(const World& world);  // gravity, relative to y = 0
double elastic_energy(const World& world);    // springs of every contact: sum of k x^2 / 2
struct ContactFigures {
  std::uint32_t contacts = 0;  // overlapping ball pairs and ball-wall contacts (0 before the first step)
  float max_overlap = 0.0f;    // largest overlap (ball-ball, ball-wall), a fraction of the smaller radius
};
// Both in one pass over the lists.
ContactFigures contact_figures(const World& world);
float max_overlap_fraction(const World& world);  // contact_figures().max_overlap
// Whether max_overlap_fraction() is past kOverlapWarning while the balls are
// near rest, and a sentence that says so (empty otherwise): a softer k than
// the scene's load allows. An impact's overlap (v sqrt(m / k): 35 % at 28 m/s)
// passes, and max_overlap_fraction() still reports it.
std::string overlap_warning(const World& world);
float pile_top(const World& world);  // highest point of any ball
// Balls whose centre is outside the tank or whose state is not finite.
std::uint32_t escaped_or_invalid(const World& world);
// FNV-1a over positions and velocities in id order: equal iff bit-identical.
std::uint64_t state_hash(const World& world);
// Where each ball id sits in the world's arrays (which the step keeps sorted by cell): entry id is its index.
std::vector<std::uint32_t> indices_by_id(const World& world);
// The mean length of the last build's lists.
double mean_neighbours(const World& world);

}  // namespace fishtank
