#pragma once
// Broad phase: a uniform grid and a Verlet neighbour list with a skin.
//
//   sort():  counting sort of balls by cell. The world reorders its arrays by
//            the result. Cells are numbered x fastest, then y, then z, inside
//            column blocks kBlockCells wide in x (block slowest): the three
//            cells x-1..x+1 of a row are then one contiguous index range (two
//            at a block's edge), so nine to eighteen ranges cover all 27
//            neighbouring cells, and a ball's neighbours one z-layer away are
//            one block's layer away in memory, not a whole tank's. A tank at
//            most kBlockCells wide is one block: plain x, y, z order.
//   build:   for each ball, every other ball closer than r_i + r_j + skin
//            (a kernel, Kernels::build_lists). Each ball writes only its own
//            list, so chunks build in parallel, and lists come out the same
//            for any thread count.
//
// The list stays valid until some ball has moved more than skin / 2 since the
// build (two balls closing by skin / 2 each could then touch unseen); the
// world checks that every step and rebuilds only then, as LAMMPS does.

#include <algorithm>
#include <cstdint>
#include <vector>

#include "common/float4.h"
#include "common/tank.h"

namespace fishtank {

// What a list build reads and writes: the cell-sorted balls and the grid, and
// the lists to fill. The build itself is a kernel (kernels.h), scalar or SIMD.
struct CellCoord {
  std::int32_t x, y, z;
};

// Cells per block in x (see sort() above).
constexpr int kBlockCells = 16;

struct ListBuild {
  const Float4* pos;  // sorted by cell; index n and a few after it are far-away ghosts
  std::uint32_t n;
  const std::uint32_t* cell_start;  // per cell number, its first ball; one extra at the end
  const CellCoord* ball_cell;       // per ball, its cell
  int nx, ny, nz;                   // cells per axis
  int block;                        // cells per block in x
  float skin;
  std::uint32_t* neighbours;  // out: ball i's list at i * stride, ghost-padded
  std::uint32_t* counts;      // out: the true count, which may exceed stride
  std::uint32_t stride;
  std::uint32_t* batch_order;  // out, SIMD builds only: per step batch, its balls by count (kernels_simd_ball.h)
};

// Ball i's count neighbours are in place: record the count and fill the rest
// of the row with the ghost's index. The SIMD kernels walk the rows of a group
// of balls side by side, as far as the group's longest list, and read ghosts
// where a shorter one has ended.
inline std::uint32_t finish_list(const ListBuild& b, std::uint32_t i, std::uint32_t count) {
  b.counts[i] = count;
  std::uint32_t* list = b.neighbours + std::size_t(i) * b.stride;
  std::fill(list + std::min(count, b.stride), list + b.stride, b.n);
  return count;
}

// Ghost slots after the last ball: a SIMD build reads up to three balls past
// the end of a cell range, so arrays hold n + kGhostSlots entries, each a
// ghost parked where it touches nothing.
constexpr std::uint32_t kGhostSlots = 4;
constexpr Float4 kGhostPos{1e6f, 1e6f, 1e6f, 0.0f};

// The number of cell (x, y, z) in the sort order.
inline std::size_t cell_number(int x, int y, int z, int ny, int nz, int block) {
  const int x_block = x / block;
  return ((std::size_t(x_block) * nz + z) * ny + y) * block + (x - x_block * block);
}

// Calls visit(j_begin, j_end) for the index ranges (a row of up to three
// cells, split where it crosses a block edge, for each of nine rows) that
// hold every ball of ball i's 27 cells.
template <class Visit>
inline void for_each_neighbour_range(const ListBuild& b, std::uint32_t i, Visit visit) {
  const CellCoord c = b.ball_cell[i];
  const int x_lo = c.x > 0 ? c.x - 1 : 0, x_hi = c.x + 1 < b.nx ? c.x + 1 : b.nx - 1;
  // Where the row splits: the first cell of the second block, or past x_hi.
  const int split = x_lo / b.block != x_hi / b.block ? x_hi / b.block * b.block : x_hi + 1;
  for (int z = c.z > 0 ? c.z - 1 : 0; z <= c.z + 1 && z < b.nz; ++z) {
    for (int y = c.y > 0 ? c.y - 1 : 0; y <= c.y + 1 && y < b.ny; ++y) {
      visit(b.cell_start[cell_number(x_lo, y, z, b.ny, b.nz, b.block)],
            b.cell_start[cell_number(split - 1, y, z, b.ny, b.nz, b.block) + 1]);
      if (split <= x_hi)
        visit(b.cell_start[cell_number(split, y, z, b.ny, b.nz, b.block)],
              b.cell_start[cell_number(x_hi, y, z, b.ny, b.nz, b.block) + 1]);
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
  const std::uint32_t* batch_order() const { return batch_order_.data(); }

 private:
  CellCoord cell_of(const Float4& p) const;

  TankBounds tank_;
  float skin_ = 0.0f;
  int nx_ = 1, ny_ = 1, nz_ = 1;
  int block_ = 1;  // cells per block in x: min(kBlockCells, nx_)
  Vec3 inv_edge_;
  std::vector<std::uint32_t> cell_start_;  // per cell number, first sorted index; one extra at the end
  std::vector<CellCoord> sorted_cell_;     // per sorted ball, its cell
  std::vector<CellCoord> scratch_cell_;
  std::vector<std::uint32_t> scratch_number_;
  std::uint32_t stride_ = 0;
  std::vector<std::uint32_t> neighbours_;
  std::vector<std::uint32_t> counts_;
  std::vector<std::uint32_t> batch_order_;
};

}  // namespace fishtank
