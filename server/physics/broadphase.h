#pragma once
// Broad phase: a uniform grid and a Verlet neighbour list with a skin.
//
//   sort():  counting sort of balls by cell, x fastest, then y, then z,
//            inside column blocks kBlockCells wide in x: a row's cells
//            x-1..x+1 are one index range, so nine to eighteen ranges cover
//            the 27 neighbouring cells, and the next z-layer is one block's
//            layer away in memory, not a whole tank's.
//   build:   for each ball, every ball closer than r_i + r_j + skin
//            (Kernels::build_lists); each batch writes only its own stretch.
//
// A list stays valid while no ball has moved more than skin / 2 since the
// build (LAMMPS's criterion); past that the world keeps it while the few
// balls that strayed further touch only balls in their lists (misses_contact).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <type_traits>
#include <variant>
#include <vector>

#include "common/float4.h"
#include "common/tank.h"

namespace fishtank {

// The lists' layout. A batch of kStepBatch balls keeps its lists from
// neighbours + first * stride, packed: its balls in groups of `lanes` (in
// batch_order), each group as many blocks as its longest list, a block
// holding the next neighbour of each ball of the group, or the ghost (index
// n) past a list's end. With one lane (the scalar twin) that is each ball's
// list after the previous one's; with four or eight a block is one vector's
// neighbours. An entry is a byte offset (list_entry): an address takes it
// with no shift, as x86 scales an index by 8 at most.
//
// The SIMD builds also write per group a record of four 32-bit words per
// ball, at group_records + 4 * (its place in batch_order): the lanes' x at
// the build, then y, then z, then their list entries (write_group_record),
// so the step loads aligned vectors; and its block count at group_blocks + place / lanes.
constexpr std::uint32_t kStepBatch = 128;

// The end of the batch that holds ball `first`, within [.., end).
inline std::uint32_t batch_end(std::uint32_t first, std::uint32_t end) {
  return std::min(end, (first / kStepBatch + 1) * kStepBatch);
}

inline std::uint32_t list_entry(std::uint32_t index) { return index * std::uint32_t(sizeof(Float4)); }
inline std::uint32_t listed_index(std::uint32_t entry) { return entry / std::uint32_t(sizeof(Float4)); }

// The row of an array of balls (positions, velocities) that a list entry names.
template <class Row>
inline Row& listed(Row* rows, std::uint32_t entry) {
  using Byte = std::conditional_t<std::is_const_v<Row>, const char, char>;
  return *reinterpret_cast<Row*>(reinterpret_cast<Byte*>(rows) + entry);
}

// Balls in a batch's groups: count rounded up to a multiple of lanes (the
// last group of a short batch repeats its last ball).
inline std::uint32_t grouped_length(std::uint32_t count, std::uint32_t lanes) {
  return (count + lanes - 1) / lanes * lanes;
}

// The record of the group of `lanes` balls group[0..lanes) (see above).
inline void write_group_record(const Float4* pos, const std::uint32_t* group, std::uint32_t lanes,
                               std::uint32_t* record) {
  for (std::uint32_t l = 0; l < lanes; ++l) {
    const Float4& p = pos[group[l]];
    std::memcpy(record + l, &p.x, sizeof p.x);
    std::memcpy(record + lanes + l, &p.y, sizeof p.y);
    std::memcpy(record + 2 * lanes + l, &p.z, sizeof p.z);
    record[3 * lanes + l] = list_entry(group[l]);
  }
}

// The balls a batch's lists name lie in [lowest, highest] (none: lowest > highest); near a chunk's
// edge they include the next chunk's, which the step asks for ahead (edge_fetches, prefetch_plan.h).
struct BatchReach {
  std::uint32_t lowest = std::numeric_limits<std::uint32_t>::max(), highest = 0;
  void add(std::uint32_t j) {
    lowest = std::min(lowest, j);
    highest = std::max(highest, j);
  }
};

// The rows a batch's lists name far from it in memory: in practice the
// neighbours across a column block's x faces (sort() above), out of reach of
// the SIMD step's prefetch ahead (kernels_simd_lists.h, is_remote_row). One row
// per cache line, up to kMost; past that a row is only fetched late.
struct RemoteRows {
  static constexpr std::uint32_t kMost = 31;
  static constexpr std::uint32_t kRowsPerLine = kCacheLineBytes / sizeof(Float4);
  std::uint32_t count = 0;
  std::uint32_t rows[kMost];  // the first row of each line

  void add(std::uint32_t row) {
    const std::uint32_t line_row = row - row % kRowsPerLine;
    if (count == kMost || std::find(rows, rows + count, line_row) != rows + count) return;
    rows[count++] = line_row;
  }
};

// What a list build (a kernel, kernels.h) reads and writes: the cell-sorted balls, the grid, the lists.
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
  Vec3 origin, edge;                // the grid's lowest corner, and its cells' size
  float skin;
  const float *x, *y, *z, *r;    // the same balls axis by axis, with the ghosts (for lanes > 1 only)
  std::uint32_t* neighbours;     // out: the lists, laid out as above
  std::uint32_t* counts;         // out: the true count, which may exceed stride
  std::uint32_t stride;          // the most entries a list may store
  std::uint32_t* batch_order;    // out: per batch, its balls in groups (room for lanes - 1 more at the end)
  BatchReach* reach;             // out, threaded builds only: per batch, the balls its stored lists name
  std::uint32_t* group_records;  // out, SIMD builds only: per group, its record (see above)
  std::uint32_t* group_blocks;   // out, SIMD builds only: per group, its number of blocks
  RemoteRows* remote_rows;       // out, SIMD builds only, unless null: per batch, its remote rows
};

// One ball's stored list: neighbour k is listed_index(first[k * lanes]).
struct ListView {
  const std::uint32_t* first;
  std::uint32_t count;
  std::uint32_t lanes;
  std::uint32_t operator[](std::uint32_t k) const { return listed_index(first[std::size_t(k) * lanes]); }
};

// The lists of the last build as a step reads them (the layout above), one
// struct per layout: a twin reads the one its build wrote (Kernels::list_lanes).
// One lane: ball i's list ends after counts[i] entries.
struct BallLists {
  const std::uint32_t* neighbours = nullptr;
  std::uint32_t stride = 0;
  const std::uint32_t* counts = nullptr;
  const Float4* at_build = nullptr;  // where the balls were at the build
};
// More lanes: per group its record (where its balls were at the build, and
// their entries) and its number of blocks.
struct GroupLists {
  const std::uint32_t* neighbours = nullptr;
  std::uint32_t stride = 0;
  const std::uint32_t* records = nullptr;
  const std::uint32_t* blocks = nullptr;
};
using StepLists = std::variant<BallLists, GroupLists>;

// A SIMD build reads up to three balls past a cell range's end: arrays hold
// n + kGhostSlots entries, the ghosts parked where they touch nothing.
constexpr std::uint32_t kGhostSlots = 4;
constexpr Float4 kGhostPos{1e6f, 1e6f, 1e6f, 0.0f};

// The number of cell (x, y, z) in the sort order.
inline std::size_t cell_number(int x, int y, int z, int ny, int nz, int block) {
  const int x_block = x / block;
  return ((std::size_t(x_block) * nz + z) * ny + y) * block + (x - x_block * block);
}

// How far ball i is from the faces of its cell on one axis, squared; at the
// tank's edge, where no cell lies behind a face, infinitely far.
struct AxisGaps {
  float below2, above2;
};
inline AxisGaps axis_gaps(float pos, float origin, float edge, int c, int cells) {
  constexpr float kNone = std::numeric_limits<float>::infinity();
  // A ball beyond the tank is in the border cell, beyond its outer face, so
  // its gap to the inner face is still the distance to the cells behind it.
  const float below = pos - (origin + float(c) * edge), above = edge - below;
  return {c == 0 ? kNone : below * below, c + 1 == cells ? kNone : above * above};
}

// Calls visit(j_begin, j_end) for index ranges holding every ball of the 27
// cells around c within r + the largest radius + skin of p, skipping cells
// beyond that reach. Ranges come in cell order, so lists do not depend on the skipping.
template <class Visit>
inline void for_each_range_within_reach(const ListBuild& b, CellCoord c, Float4 p, Visit visit) {
  // The margin covers the rounding of the cells' assignment (sort()).
  const float reach = (p.w + 0.5f * kMaxBallDiameter + b.skin) * 1.001f + 1e-3f;
  const float reach2 = reach * reach;
  const AxisGaps gx = axis_gaps(p.x, b.origin.x, b.edge.x, c.x, b.nx);
  const AxisGaps gy = axis_gaps(p.y, b.origin.y, b.edge.y, c.y, b.ny);
  const AxisGaps gz = axis_gaps(p.z, b.origin.z, b.edge.z, c.z, b.nz);
  const float gap_y[3] = {gy.below2, 0.0f, gy.above2}, gap_z[3] = {gz.below2, 0.0f, gz.above2};
  // The row's middle cell, and the cells left and right of it: in the same
  // block (one range with it) or in the neighbouring block (their own range).
  const int x_block = c.x / b.block, x_in_block = c.x - x_block * b.block;
  const std::ptrdiff_t y_step = b.block, z_step = std::ptrdiff_t(b.ny) * b.block, block_step = z_step * b.nz;
  const std::uint32_t* middle =
      b.cell_start + ((std::ptrdiff_t(x_block) * b.nz + c.z) * b.ny + c.y) * b.block + x_in_block;
  const bool left_joined = x_in_block > 0, right_joined = x_in_block + 1 < b.block;
  const std::uint32_t* left = left_joined ? middle - 1 : c.x > 0 ? middle - block_step + (b.block - 1) : middle;
  const std::uint32_t* right = right_joined     ? middle + 1
                               : c.x + 1 < b.nx ? middle + block_step - (b.block - 1)
                                                : middle;
  for (int dz = 0; dz < 3; ++dz) {
    for (int dy = 0; dy < 3; ++dy) {
      const float gap_yz = gap_y[dy] + gap_z[dz];
      // Not `>=`: a ball whose position is NaN has NaN gaps, and must not reach past the grid's edge.
      if (!(gap_yz < reach2)) continue;
      const std::ptrdiff_t row = (dz - 1) * z_step + (dy - 1) * y_step;
      const bool with_left = gap_yz + gx.below2 < reach2, with_right = gap_yz + gx.above2 < reach2;
      if (with_left && !left_joined) visit(left[row], left[row + 1]);
      visit((with_left && left_joined ? left : middle)[row], (with_right && right_joined ? right : middle)[row + 1]);
      if (with_right && !right_joined) visit(right[row], right[row + 1]);
    }
  }
}

// The ranges that hold every candidate for sorted ball i's list.
template <class Visit>
inline void for_each_neighbour_range(const ListBuild& b, std::uint32_t i, Visit visit) {
  for_each_range_within_reach(b, b.ball_cell[i], b.pos[i], visit);
}

class NeighbourList {
 public:
  // Cells are at least max diameter + skin wide, so any touching pair is in adjacent cells.
  void configure(const TankBounds& tank, float skin);

  // Fills order[new] = old for the n balls at pos.
  void sort(const Float4* pos, std::uint32_t n, std::vector<std::uint32_t>& order);

  // What a build of the lists for the n sorted balls at pos needs. A list longer than stride() is cut
  // short and its count says so: the caller then grows the stride and builds again.
  ListBuild build_view(const Float4* pos, std::uint32_t n);

  // Whether ball i, now at pos[i], touches a ball its list lacks. `moved` is the furthest any ball
  // moved since the build, so the search covers the build's cells that far around i. True past can_check.
  bool misses_contact(std::uint32_t i, const Float4* pos, const Float4* at_build, float moved) const;
  // Whether a check is worth it: while a large ball's search reaches at most kMaxCheckCells cells
  // past its own, its cost stays that of a few list builds, not growing with the cube of `moved`.
  bool can_check(float moved) const;

  // Room for `stride` neighbours of each of n balls, in groups of `lanes` (Kernels::list_lanes).
  void reserve(std::uint32_t n, std::uint32_t stride, std::uint32_t lanes);

  float skin() const { return skin_; }  // the last configure's
  std::uint32_t stride() const { return stride_; }
  const std::uint32_t* neighbours() const { return neighbours_.get(); }
  const std::uint32_t* counts() const { return counts_.data(); }
  const std::uint32_t* batch_order() const { return batch_order_.data(); }
  const BatchReach* batch_reach() const { return reach_.data(); }
  const std::uint32_t* group_records() const { return group_records_.data(); }
  const std::uint32_t* group_blocks() const { return group_blocks_.data(); }
  // The lists in the layout of the last reserve's lanes; at_build is where the balls were at the build.
  StepLists step_lists(const Float4* at_build) const {
    if (lanes_ == 1) return BallLists{neighbours(), stride_, counts(), at_build};
    return GroupLists{neighbours(), stride_, group_records(), group_blocks()};
  }
  const RemoteRows* remote_rows() const { return remote_rows_.data(); }

  // Calls visit(i, ListView) once for each ball of the last build, batch by
  // batch in the layout's order.
  template <class Visit>
  void for_each_list(Visit visit) const;

 private:
  CellCoord cell_of(const Float4& p) const;
  // Calls visit(j_begin, j_end) for index ranges that hold every ball of the
  // last build whose position lies within `reach` of p on every axis.
  template <class Visit>
  void for_each_range_in_box(const Float4& p, float reach, Visit visit) const;

  static constexpr int kMaxCheckCells = 2;  // see can_check

  Vec3 origin_;  // the grid's lowest corner: the tank's
  float skin_ = 0.0f;
  int nx_ = 1, ny_ = 1, nz_ = 1;
  int block_ = 1;  // cells per block in x: min(kBlockCells, nx_)
  Vec3 inv_edge_, edge_;
  std::vector<std::uint32_t> cell_start_;  // per cell number, first sorted index; one extra at the end
  std::vector<CellCoord> sorted_cell_;     // per sorted ball, its cell
  std::vector<CellCoord> scratch_cell_;
  std::vector<std::uint32_t> scratch_number_;
  std::vector<std::uint32_t> next_slot_;  // per cell number, the sort's next free slot
  std::uint32_t stride_ = 0;
  std::uint32_t lanes_ = 1;
  std::uint32_t listed_balls_ = 0;  // n of the last build_view
  // Left uninitialised: a build writes only what the lists take, and pages never written are never mapped.
  std::unique_ptr<std::uint32_t[]> neighbours_;
  std::size_t neighbours_room_ = 0;
  std::vector<std::uint32_t> counts_;
  std::vector<std::uint32_t> batch_order_;
  std::vector<BatchReach> reach_;
  AlignedVector<std::uint32_t> group_records_;  // SIMD builds only
  std::vector<std::uint32_t> group_blocks_;     // SIMD builds only
  std::vector<RemoteRows> remote_rows_;         // SIMD builds only
  AlignedVector<float> axes_;                   // x, y, z, radius of the sorted balls, axis by axis (ListBuild)
};

template <class Visit>
void NeighbourList::for_each_list(Visit visit) const {
  const std::uint32_t n = listed_balls_;
  for (std::uint32_t batch = 0; batch < n; batch += kStepBatch) {
    const std::uint32_t* block = neighbours_.get() + std::size_t(batch) * stride_;
    const std::uint32_t* group = batch_order_.data() + batch;
    const std::uint32_t* const groups_end = group + grouped_length(batch_end(batch, n) - batch, lanes_);
    for (; group < groups_end; group += lanes_) {
      std::uint32_t blocks = 0;
      for (std::uint32_t l = 0; l < lanes_; ++l) {
        const std::uint32_t count = std::min(counts_[group[l]], stride_);
        blocks = std::max(blocks, count);
        if (l == 0 || group[l] != group[l - 1]) visit(group[l], ListView{block + l, count, lanes_});
      }
      block += std::size_t(blocks) * lanes_;
    }
  }
}

}  // namespace fishtank
