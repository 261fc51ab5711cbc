#pragma once
// Pours queued balls in at the top of the tank.
//
// Candidate slots form a lattice one largest diameter apart just under the
// ceiling; each queued ball tries the slots in a shuffled order, jittered
// within its slot, and is placed only where it overlaps no ball, no player and
// no ball placed in the same round. What does not fit waits for the next round,
// so a pile that reaches the top simply holds the rest back until room appears.

#include <cstdint>
#include <deque>
#include <random>
#include <vector>

#include "common/float4.h"
#include "common/tank.h"

namespace fishtank {

struct NewBall {
  int kind;
  Float4 pos;  // x, y, z, radius
  Float4 vel;  // vx, vy, vz, mass
};

class Spawner {
 public:
  // The slots' lattice fits the tank given here, the one place() is then given.
  Spawner(const TankBounds& tank, std::uint64_t seed);

  // Queues count balls; kinds take turns so every kind gets an equal share.
  void enqueue(std::uint32_t count);
  std::uint32_t pending() const { return static_cast<std::uint32_t>(queue_.size()); }

  // Moves as many queued balls as fit into `placed`.
  void place(const TankBounds& tank, const Float4* pos, std::uint32_t n, const Float4* players, int player_count,
             std::vector<NewBall>& placed);

  static constexpr float kEntrySpeed = 3.0f;  // m/s downward, so a layer clears quickly

 private:
  float uniform();  // [0, 1), the same on every platform

  std::mt19937_64 rng_;
  std::deque<int> queue_;
  int next_kind_ = 0;
  int slots_x_, slots_z_;
  float slot_edge_x_, slot_edge_z_;
  std::vector<std::uint32_t> slot_order_;
  std::vector<std::vector<std::uint32_t>> near_top_;  // per slot, balls that reach the entry layer
  std::size_t first_placed_ = 0;                      // where this round starts in `placed`
};

}  // namespace fishtank
