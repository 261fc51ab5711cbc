#pragma once
// Broad phase: a uniform grid and a Verlet neighbour list with a skin.
//
//   sort():  counting sort of balls by cell, x fastest. The world reorders its
//            arrays by the result, so the three cells x-1..x+1 of a grid row
//            are one contiguous index range and nine ranges cover all 27
//            neighbouring cells.
//   build(): for each ball, every other ball closer than r_i + r_j + skin.
//            Each ball writes only its own list, so chunks build in parallel,
//            and lists come out the same for any thread count.
//
// The list stays valid until some ball has moved more than skin / 2 since the
// build (two balls closing by skin / 2 each could then touch unseen); the
// world checks that every step and rebuilds only then, as LAMMPS does.

#include <cstdint>
#include <vector>

#include "common/float4.h"
#include "common/tank.h"

namespace fishtank {

class NeighbourList {
 public:
  // Cells are at least max diameter + skin wide, so any touching pair is in adjacent cells.
  void configure(const TankBounds& tank, float skin);

  // Fills order[new] = old for the n balls at pos.
  void sort(const Float4* pos, std::uint32_t n, std::vector<std::uint32_t>& order);

  // Lists for balls [begin, end) of the sorted arrays. Returns the longest list
  // seen, which may exceed stride(): then the caller grows the stride and builds again.
  std::uint32_t build(const Float4* pos, std::uint32_t n, std::uint32_t begin, std::uint32_t end);

  // Room for `stride` neighbours of each of n balls.
  void reserve(std::uint32_t n, std::uint32_t stride);

  std::uint32_t stride() const { return stride_; }
  const std::uint32_t* neighbours() const { return neighbours_.data(); }
  const std::uint32_t* counts() const { return counts_.data(); }

 private:
  std::uint32_t cell_of(const Float4& p) const;

  TankBounds tank_;
  float skin_ = 0.0f;
  int nx_ = 1, ny_ = 1, nz_ = 1;
  Vec3 inv_edge_;
  std::vector<std::uint32_t> cell_start_;   // per cell, first sorted index; one extra at the end
  std::vector<std::uint32_t> sorted_cell_;  // per sorted ball, its cell
  std::vector<std::uint32_t> scratch_cell_;
  std::uint32_t stride_ = 0;
  std::vector<std::uint32_t> neighbours_;
  std::vector<std::uint32_t> counts_;
};

}  // namespace fishtank
