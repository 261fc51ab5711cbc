#pragma once
// Broad phase: a uniform grid and a Verlet neighbour list with a skin.
//
//   sort():  counting sort of balls by cell, x fastest. The world reorders its
//            arrays by the result, so the three cells x-1..x+1 of a grid row
//            are one contiguous index range and nine ranges cover all 27
//            neighbouring cells.
//   build:   for each ball, every other ball closer than r_i + r_j + skin
//            (a kernel, Kernels::build_lists). Each ball writes only its own
//            list, so chunks build in parallel, and lists come out the same
//            for any thread count.
//
// The list stays valid until some ball has moved more than skin / 2 since the
// build (two balls closing by skin / 2 each could then touch unseen); the
// world checks that every step and rebuilds only then, as LAMMPS does.

#include <cstdint>
#include <vector>

#include "common/float4.h"
#include "common/tank.h"

namespace fishtank {

// What a list build reads and writes: the cell-sorted balls and the grid, and
// the lists to fill. The build itself is a kernel (kernels.h), scalar or SIMD.
struct ListBuild {
  const Float4* pos;  // sorted by cell; index n and a few after it are far-away ghosts
  std::uint32_t n;
  const std::uint32_t* cell_start;  // per cell, its first ball; one extra at the end
  const std::uint32_t* ball_cell;   // per ball, its cell
  int nx, ny, nz;                   // cells per axis, x fastest
  float skin;
  std::uint32_t* neighbours;  // out: ball i's list at i * stride, ghost-padded
  std::uint32_t* counts;      // out: the true count, which may exceed stride
  std::uint32_t stride;
};

// Lists are padded with the ghost's index to a multiple of the widest
// kernel's lanes; a narrower kernel reads a shorter prefix.
constexpr std::uint32_t kListPadding = 8;
inline std::uint32_t padded_neighbour_count(std::uint32_t count, std::uint32_t lanes) {
  return (count + lanes - 1) / lanes * lanes;
}

// Ball i's count neighbours are in place: record the count and pad with the ghost.
inline std::uint32_t finish_list(const ListBuild& b, std::uint32_t i, std::uint32_t count) {
  b.counts[i] = count;
  std::uint32_t* list = b.neighbours + std::size_t(i) * b.stride;
  const std::uint32_t padded = padded_neighbour_count(count, kListPadding);
  for (std::uint32_t k = count; k < padded && k < b.stride; ++k) list[k] = b.n;
  return count;
}

// Ghost slots after the last ball: a SIMD build reads up to three balls past
// the end of a cell range, so arrays hold n + kGhostSlots entries.
constexpr std::uint32_t kGhostSlots = 4;

// Calls visit(j_begin, j_end) for the nine index ranges (three rows of three
// cells in each of three layers) that hold every ball of ball i's 27 cells.
template <class Visit>
inline void for_each_neighbour_range(const ListBuild& b, std::uint32_t i, Visit visit) {
  const int cell = static_cast<int>(b.ball_cell[i]);
  const int cx = cell % b.nx, cy = (cell / b.nx) % b.ny, cz = cell / (b.nx * b.ny);
  const int x_lo = cx > 0 ? cx - 1 : 0, x_hi = cx + 1 < b.nx ? cx + 1 : b.nx - 1;
  for (int z = cz > 0 ? cz - 1 : 0; z <= cz + 1 && z < b.nz; ++z) {
    for (int y = cy > 0 ? cy - 1 : 0; y <= cy + 1 && y < b.ny; ++y) {
      const std::size_t row = std::size_t(b.nx) * (y + std::size_t(b.ny) * z);
      visit(b.cell_start[row + x_lo], b.cell_start[row + x_hi + 1]);
    }
  }
}

class NeighbourList {
 public:
  // Cells are at least max diameter + skin wide, so any touching pair is in adjacent cells.
  void configure(const TankBounds& tank, float skin);

  // Fills order[new] = old for the n balls at pos.
  void sort(const Float4* pos, std::uint32_t n, std::vector<std::uint32_t>& order);

  // What a build of the lists for the n sorted balls at pos needs (see
  // Kernels::build_lists). A list longer than stride() is cut short and its
  // count says so: the caller then grows the stride and builds again.
  ListBuild build_view(const Float4* pos, std::uint32_t n);

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
