#include "server/physics/broadphase.h"

#include <algorithm>

namespace fishtank {

void NeighbourList::configure(const TankBounds& tank, float skin) {
  origin_ = tank.min;
  skin_ = skin;
  const float min_edge = kMaxBallDiameter + skin;
  Vec3 size = tank.size();
  nx_ = std::max(1, static_cast<int>(size.x / min_edge));
  ny_ = std::max(1, static_cast<int>(size.y / min_edge));
  nz_ = std::max(1, static_cast<int>(size.z / min_edge));
  inv_edge_ = {nx_ / size.x, ny_ / size.y, nz_ / size.z};
  edge_ = {size.x / nx_, size.y / ny_, size.z / nz_};
  block_ = std::min(kBlockCells, nx_);
  const int blocks = (nx_ + block_ - 1) / block_;  // the last may be part empty
  cell_start_.assign(std::size_t(blocks) * block_ * ny_ * nz_ + 1, 0);
}

CellCoord NeighbourList::cell_of(const Float4& p) const {
  // Clamped before the conversion, which then rounds down: balls pushed
  // outside the tank go to the border cell, which still finds all their
  // neighbours, and NaN fails the first comparison and goes to cell 0.
  // Comparisons, not std::fmax and std::fmin, which this build calls in libm.
  auto axis = [](float pos, float lo, float inv_edge, int cells) {
    const float c = std::max(0.0f, (pos - lo) * inv_edge);
    return static_cast<std::int32_t>(std::min(c, float(cells - 1)));
  };
  return {axis(p.x, origin_.x, inv_edge_.x, nx_), axis(p.y, origin_.y, inv_edge_.y, ny_),
          axis(p.z, origin_.z, inv_edge_.z, nz_)};
}

void NeighbourList::sort(const Float4* pos, std::uint32_t n, std::vector<std::uint32_t>& order) {
  scratch_cell_.resize(n);
  scratch_number_.resize(n);
  std::fill(cell_start_.begin(), cell_start_.end(), 0u);
  for (std::uint32_t i = 0; i < n; ++i) {
    const CellCoord c = scratch_cell_[i] = cell_of(pos[i]);
    scratch_number_[i] = static_cast<std::uint32_t>(cell_number(c.x, c.y, c.z, ny_, nz_, block_));
    ++cell_start_[scratch_number_[i] + 1];
  }
  for (std::size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];

  order.resize(n);
  sorted_cell_.resize(n);
  next_slot_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (std::uint32_t i = 0; i < n; ++i) {
    std::uint32_t slot = next_slot_[scratch_number_[i]]++;
    order[slot] = i;
    sorted_cell_[slot] = scratch_cell_[i];
  }
}

void NeighbourList::reserve(std::uint32_t n, std::uint32_t stride, std::uint32_t lanes) {
  stride_ = std::max(stride, 1u);
  lanes_ = lanes;
  // The last batch's groups may repeat a ball to fill their lanes.
  const std::size_t room = (std::size_t(n) + lanes - 1) * stride_;
  if (room > neighbours_room_) {  // a build rewrites the lists: nothing to keep
    neighbours_.reset(new std::uint32_t[room]);
    neighbours_room_ = room;
  }
  counts_.resize(n);
  batch_order_.resize(std::size_t(n) + lanes - 1);
  reach_.resize((std::size_t(n) + kStepBatch - 1) / kStepBatch);
  if (lanes > 1) {
    group_records_.resize(4 * (std::size_t(n) + lanes - 1));
    group_blocks_.resize((std::size_t(n) + lanes - 1) / lanes);
    remote_rows_.resize(reach_.size());
  }
}

bool NeighbourList::can_check(float moved) const {
  const float reach = kMaxBallDiameter + moved;  // a large ball's
  return reach <= kMaxCheckCells * std::min({edge_.x, edge_.y, edge_.z});
}

template <class Visit>
void NeighbourList::for_each_range_in_box(const Float4& p, float reach, Visit visit) const {
  // The margin covers the rounding of the cells' assignment (sort()): cell_of
  // rounds monotonically, so a ball within reach is in a cell between these.
  const float wide = reach * 1.001f + 1e-3f;
  const CellCoord lo = cell_of({p.x - wide, p.y - wide, p.z - wide, 0.0f});
  const CellCoord hi = cell_of({p.x + wide, p.y + wide, p.z + wide, 0.0f});
  for (int z = lo.z; z <= hi.z; ++z)
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x;) {  // a row's cells are one range per block
        const int last = std::min(hi.x, (x / block_ + 1) * block_ - 1);
        visit(cell_start_[cell_number(x, y, z, ny_, nz_, block_)],
              cell_start_[cell_number(last, y, z, ny_, nz_, block_) + 1]);
        x = last + 1;
      }
}

bool NeighbourList::misses_contact(std::uint32_t i, const Float4* pos, const Float4* at_build, float moved) const {
  // Relative margins keep the answer on the safe side of float rounding: a
  // pair counts as touching a little early, and as listed only if it was
  // clearly inside the build's cutoff.
  constexpr float kTouchMargin = 1.0f + 1e-5f, kListedMargin = 1.0f - 1e-5f;
  const Float4 p = pos[i], b = at_build[i];
  if (!can_check(moved)) return true;
  // A ball touching i now was at the build within r_i + r_j + moved of p.
  const float reach = p.w + 0.5f * kMaxBallDiameter + moved;
  bool missing = false;
  for_each_range_in_box(p, reach, [&](std::uint32_t j_begin, std::uint32_t j_end) {
    for (std::uint32_t j = j_begin; j < j_end && !missing; ++j) {
      const Float4 q = pos[j], qb = at_build[j];
      const float dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z, touch = p.w + q.w;
      const float bx = b.x - qb.x, by = b.y - qb.y, bz = b.z - qb.z, cutoff = touch + skin_;
      missing = j != i && dx * dx + dy * dy + dz * dz < touch * touch * kTouchMargin &&
                !(bx * bx + by * by + bz * bz < cutoff * cutoff * kListedMargin);
    }
  });
  return missing;
}

ListBuild NeighbourList::build_view(const Float4* pos, std::uint32_t n) {
  listed_balls_ = n;
  // The SIMD builds test four or eight consecutive candidates with one load
  // per axis, so they read the positions copied axis by axis.
  const std::size_t len = n + kGhostSlots;
  float *x = nullptr, *y = nullptr, *z = nullptr, *r = nullptr;
  if (lanes_ > 1) {
    axes_.resize(4 * len);
    x = axes_.data(), y = x + len, z = y + len, r = z + len;
    for (std::size_t k = 0; k < len; ++k) {
      x[k] = pos[k].x;
      y[k] = pos[k].y;
      z[k] = pos[k].z;
      r[k] = pos[k].w;
    }
  }
  ListBuild b{};
  b.cell_start = cell_start_.data();
  b.nx = nx_, b.ny = ny_, b.nz = nz_, b.block = block_;
  b.origin = origin_, b.edge = edge_, b.skin = skin_;
  b.pos = pos, b.n = n, b.ball_cell = sorted_cell_.data();
  b.x = x, b.y = y, b.z = z, b.r = r;
  b.neighbours = neighbours_.get(), b.counts = counts_.data(), b.stride = stride_;
  b.batch_order = batch_order_.data();
  b.reach = reach_.data();
  b.group_records = group_records_.data(), b.group_blocks = group_blocks_.data();
  b.remote_rows = remote_rows_.data();
  return b;
}

}  // namespace fishtank
