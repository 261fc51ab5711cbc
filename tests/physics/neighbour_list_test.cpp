// Every list-build kernel finds exactly the pairs within r_i + r_j + skin, in
// the same order, however many of the neighbouring cells a ball's reach lets
// it skip, reports lists that do not fit instead of overrunning, says which
// balls each batch's lists reach, and gives each SIMD group its record and
// each batch its remote rows.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "tests/physics/scenarios.h"

using namespace fishtank;
using namespace fishtank::test;

namespace {

struct Lists {
  std::vector<std::uint32_t> counts;
  std::vector<std::vector<std::uint32_t>> entries;  // the stored part of each list
  AlignedVector<Float4> pos;                        // the balls in the sorted order entries index
  std::uint32_t longest = 0;
  std::size_t remote_lines_well_away = 0;  // SIMD builds: lines of rows named 32 batches or more from their batch
};

// n random balls of every kind, packed densely enough that many lists are long;
// every 16th up to `overhang` units past the tank's faces, as balls pushed
// through a wall are (the grid keeps them in its border cells).
AlignedVector<Float4> random_balls(const TankBounds& tank, std::uint32_t n, float overhang = 0.0f) {
  std::mt19937 rng(5);
  auto axis = [](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi); };
  auto x = axis(tank.min.x, tank.max.x), y = axis(tank.min.y, tank.max.y), z = axis(tank.min.z, tank.max.z);
  auto far_x = axis(tank.min.x - overhang, tank.max.x + overhang),
       far_y = axis(tank.min.y - overhang, tank.max.y + overhang),
       far_z = axis(tank.min.z - overhang, tank.max.z + overhang);
  AlignedVector<Float4> pos(n + kGhostSlots, kGhostPos);
  for (std::uint32_t i = 0; i < n; ++i) {
    const float radius = 0.5f * kBallKinds[i % kKindCount].diameter;
    pos[i] = i % 16 == 0 ? Float4{far_x(rng), far_y(rng), far_z(rng), radius} : Float4{x(rng), y(rng), z(rng), radius};
  }
  return pos;
}

Lists build(const Kernels& kernels, const TankBounds& tank, const AlignedVector<Float4>& unsorted, std::uint32_t n,
            std::uint32_t stride) {
  NeighbourList list;
  list.configure(tank, 0.2f);
  std::vector<std::uint32_t> order;
  list.sort(unsorted.data(), n, order);
  AlignedVector<Float4> pos(unsorted);
  for (std::uint32_t k = 0; k < n; ++k) pos[k] = unsorted[order[k]];
  list.reserve(n, stride, kernels.list_lanes);
  Lists out;
  out.pos = pos;
  out.longest = kernels.build_lists(list.build_view(pos.data(), n), 0, n);
  out.counts.assign(list.counts(), list.counts() + n);
  out.entries.resize(n);
  std::vector<int> seen(n, 0);
  list.for_each_list([&](std::uint32_t i, ListView l) {
    ++seen[i];
    for (std::uint32_t k = 0; k < l.count; ++k) out.entries[i].push_back(l[k]);
  });
  // The layout holds each ball's list exactly once, nearest first by
  // d^2 - (r_i + r_j)^2 (order_nearest_first).
  REQUIRE(std::count(seen.begin(), seen.end(), 1) == std::ptrdiff_t(n));
  for (std::uint32_t i = 0; i < n; ++i) {
    auto nearness = [&](std::uint32_t j) {
      const float dx = pos[j].x - pos[i].x, dy = pos[j].y - pos[i].y, dz = pos[j].z - pos[i].z;
      const float reach = pos[i].w + pos[j].w;
      return dx * dx + dy * dy + dz * dz - reach * reach;
    };
    const std::vector<std::uint32_t>& l = out.entries[i];
    INFO("ball " << i);
    REQUIRE(std::is_sorted(l.begin(), l.end(),
                           [&](std::uint32_t a, std::uint32_t b) { return nearness(a) < nearness(b); }));
  }
  // Each batch's reach is the lowest and the highest ball its lists name
  // (the threaded builds say: only they have chunk edges to look after).
  for (std::uint32_t batch = 0; kernels.threaded && batch * kStepBatch < n; ++batch) {
    BatchReach expected;
    for (std::uint32_t i = batch * kStepBatch; i < batch_end(batch * kStepBatch, n); ++i)
      for (std::uint32_t j : out.entries[i]) expected.add(j);
    INFO("batch " << batch);
    REQUIRE(list.batch_reach()[batch].lowest == expected.lowest);
    REQUIRE(list.batch_reach()[batch].highest == expected.highest);
  }
  // Each group's record (SIMD builds) holds its balls' positions at the build
  // and their list entries, lane by lane, and its block count is its longest
  // stored list.
  const std::uint32_t lanes = kernels.list_lanes;
  for (std::uint32_t batch = 0; lanes > 1 && batch < n; batch += kStepBatch) {
    const std::uint32_t grouped = grouped_length(batch_end(batch, n) - batch, lanes);
    for (std::uint32_t place = batch; place < batch + grouped; place += lanes) {
      const std::uint32_t* record = list.group_records() + 4 * std::size_t(place);
      std::uint32_t longest = 0;
      for (std::uint32_t l = 0; l < lanes; ++l) {
        const std::uint32_t ball = list.batch_order()[place + l];
        float x, y, z;
        std::memcpy(&x, record + l, sizeof x);
        std::memcpy(&y, record + lanes + l, sizeof y);
        std::memcpy(&z, record + 2 * lanes + l, sizeof z);
        INFO("group at " << place << ", lane " << l);
        REQUIRE((x == pos[ball].x && y == pos[ball].y && z == pos[ball].z));
        REQUIRE(record[3 * lanes + l] == list_entry(ball));
        longest = std::max(longest, std::min(out.counts[ball], stride));
      }
      REQUIRE(list.group_blocks()[place / lanes] == longest);
    }
  }
  // Each batch's remote rows (SIMD builds) are distinct lines of rows that its
  // lists name, none of its own, and include every line they name 32 batches
  // or more away (the step's window is narrower), while there is room.
  constexpr std::uint32_t kRowsPerLine = RemoteRows::kRowsPerLine, kWellAway = 32 * kStepBatch;
  for (std::uint32_t batch = 0; lanes > 1 && batch < n; batch += kStepBatch) {
    const RemoteRows& remote = list.remote_rows()[batch / kStepBatch];
    std::vector<std::uint32_t> named, noted(remote.rows, remote.rows + remote.count), well_away;
    for (std::uint32_t i = batch; i < batch_end(batch, n); ++i)
      for (std::uint32_t j : out.entries[i]) {
        named.push_back(j / kRowsPerLine * kRowsPerLine);
        if (j + kWellAway <= batch || j >= batch + kWellAway) well_away.push_back(named.back());
      }
    std::sort(named.begin(), named.end());
    std::sort(noted.begin(), noted.end());
    std::sort(well_away.begin(), well_away.end());
    well_away.erase(std::unique(well_away.begin(), well_away.end()), well_away.end());
    INFO("batch from ball " << batch);
    REQUIRE(std::adjacent_find(noted.begin(), noted.end()) == noted.end());
    REQUIRE(std::includes(named.begin(), named.end(), noted.begin(), noted.end()));
    for (std::uint32_t row : noted) REQUIRE((row + kRowsPerLine <= batch || row >= batch + kStepBatch));
    if (remote.count < RemoteRows::kMost)
      REQUIRE(std::includes(noted.begin(), noted.end(), well_away.begin(), well_away.end()));
    out.remote_lines_well_away += well_away.size();
  }
  return out;
}

}  // namespace

TEST_CASE("every list build finds the same neighbours as a brute-force search", "[physics][broadphase]") {
  // 20 units: 6 cells across, one block; 60 units: 18 cells, a full block of
  // kBlockCells and a part-empty one, so rows split at the block edge.
  const float width = GENERATE(20.0f, 60.0f);
  // Balls past the walls sit in the border cells but outside them: the
  // cells a ball's reach skips must be worked out for them too.
  const float overhang = GENERATE(0.0f, 3.0f);
  TankBounds tank;
  tank.min = {-0.5f * width, 0.0f, -10.0f};
  tank.max = {0.5f * width, 20.0f, 10.0f};
  const std::uint32_t n = static_cast<std::uint32_t>(150 * width);
  INFO("tank " << width << " units wide, " << n << " balls, some up to " << overhang << " units outside");
  const AlignedVector<Float4> balls = random_balls(tank, n, overhang);
  const Lists scalar = build(kScalarKernels, tank, balls, n, 96);
  REQUIRE(scalar.longest <= 96);

  // Brute force over the same sorted order: the scalar build is the reference.
  NeighbourList grid;
  grid.configure(tank, 0.2f);
  std::vector<std::uint32_t> order;
  grid.sort(balls.data(), n, order);
  std::size_t pairs = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    std::vector<std::uint32_t> expected;
    const Float4& a = balls[order[i]];
    for (std::uint32_t j = 0; j < n; ++j) {
      const Float4& b = balls[order[j]];
      const float dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z, cut = a.w + b.w + 0.2f;
      if (j != i && dx * dx + dy * dy + dz * dz < cut * cut) expected.push_back(j);
    }
    std::vector<std::uint32_t> got = scalar.entries[i];
    std::sort(got.begin(), got.end());
    REQUIRE(got == expected);
    pairs += expected.size();
  }
  REQUIRE(pairs > 10 * n);  // dense enough that lists span several SIMD blocks

  for (const std::string& name : variant_names()) {
    INFO(name);
    const Lists simd = build(kernels_named(name), tank, balls, n, 96);
    CHECK(simd.counts == scalar.counts);
    CHECK(simd.entries == scalar.entries);  // same neighbours in the same order
    if (width == 60.0f && kernels_named(name).list_lanes > 1)
      CHECK(simd.remote_lines_well_away > 0);  // rows across the block edge are remote
  }
}

TEST_CASE("a list longer than the stride is counted in full and keeps stride of its entries", "[physics][broadphase]") {
  TankBounds tank;
  tank.min = {-10.0f, 0.0f, -10.0f};
  tank.max = {10.0f, 20.0f, 10.0f};
  const std::uint32_t n = 3000;
  const AlignedVector<Float4> balls = random_balls(tank, n);
  const Lists full = build(kScalarKernels, tank, balls, n, 64);
  for (const std::string& name : variant_names()) {
    INFO(name);
    const Lists cut = build(kernels_named(name), tank, balls, n, 8);
    CHECK(cut.longest == full.longest);
    CHECK(cut.counts == full.counts);
    std::size_t shortened = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      // The stored part is as long as the stride allows, and all of it from the full list.
      const std::vector<std::uint32_t>& f = full.entries[i];
      std::vector<std::uint32_t> kept = cut.entries[i], all = f;
      REQUIRE(kept.size() == std::min<std::size_t>(f.size(), 8));
      std::sort(kept.begin(), kept.end());
      std::sort(all.begin(), all.end());
      REQUIRE(std::includes(all.begin(), all.end(), kept.begin(), kept.end()));
      shortened += f.size() > 8;
    }
    CHECK(shortened > n / 10);  // the case this test is for
  }
}

TEST_CASE("neighbours at equal distances are all kept, in the order found", "[physics][broadphase]") {
  // Unit balls on a cubic lattice of unit spacing, at whole and half
  // coordinates so every distance is exact: each inner ball's six nearest
  // neighbours share one key, d^2 - (r_i + r_j)^2 = 0, and the diagonal ones
  // (d = 1.41) are beyond the reach of 1.2. The orderings give equal keys
  // one place each, in the order the build found them.
  TankBounds tank;
  tank.min = {-10.0f, 0.0f, -10.0f};
  tank.max = {10.0f, 20.0f, 10.0f};
  constexpr int kSide = 10;
  const std::uint32_t n = kSide * kSide * kSide;
  AlignedVector<Float4> balls(n + kGhostSlots, kGhostPos);
  for (int a = 0; a < kSide; ++a)
    for (int b = 0; b < kSide; ++b)
      for (int c = 0; c < kSide; ++c)
        balls[(a * kSide + b) * kSide + c] = {-4.5f + float(a), 0.5f + float(b), -4.5f + float(c), 0.5f};
  const Lists scalar = build(kScalarKernels, tank, balls, n, 32);
  const AlignedVector<Float4>& pos = scalar.pos;
  std::size_t six = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    std::vector<std::uint32_t> expected;  // one unit away along one axis
    for (std::uint32_t j = 0; j < n; ++j)
      if (std::abs(pos[j].x - pos[i].x) + std::abs(pos[j].y - pos[i].y) + std::abs(pos[j].z - pos[i].z) == 1.0f)
        expected.push_back(j);
    std::vector<std::uint32_t> got = scalar.entries[i];
    std::sort(got.begin(), got.end());
    INFO("ball " << i);
    REQUIRE(got == expected);
    six += got.size() == 6;
  }
  CHECK(six == (kSide - 2) * (kSide - 2) * (kSide - 2));  // the inner balls

  for (const std::string& name : variant_names()) {
    INFO(name);
    const Lists simd = build(kernels_named(name), tank, balls, n, 32);
    CHECK(simd.counts == scalar.counts);
    CHECK(simd.entries == scalar.entries);
  }
}

TEST_CASE("a ball whose position is NaN searches only cells of the grid, even in a grid one cell deep",
          "[physics][broadphase]") {
  // One cell across in x and z, three in y: a NaN ball goes to cell 0 (cell_of), where every cell below or
  // beside lies outside the grid. A blown-up run (the accuracy tool's stability map) made such balls.
  TankBounds tank;
  tank.min = {-2.0f, 0.0f, -2.0f};
  tank.max = {2.0f, 10.0f, 2.0f};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  AlignedVector<Float4> pos(3 + kGhostSlots, kGhostPos);
  pos[0] = {0.0f, 1.0f, 0.0f, 0.5f};
  pos[1] = {0.0f, nan, 0.0f, 0.5f};
  pos[2] = {0.0f, 1.5f, 0.0f, 0.5f};
  NeighbourList grid;
  grid.configure(tank, 0.2f);
  std::vector<std::uint32_t> order;
  grid.sort(pos.data(), 3, order);
  AlignedVector<Float4> sorted(pos);
  for (std::uint32_t k = 0; k < 3; ++k) sorted[k] = pos[order[k]];
  grid.reserve(3, 8, 1);
  const ListBuild b = grid.build_view(sorted.data(), 3);
  for (std::uint32_t i = 0; i < 3; ++i) {
    INFO("ball " << order[i]);
    int ranges = 0;
    for_each_neighbour_range(b, i, [&](std::uint32_t j_begin, std::uint32_t j_end) {
      ++ranges;
      CHECK(j_begin <= j_end);
      CHECK(j_end <= 3u);
    });
    CHECK(ranges >= 1);  // its own cell
    CHECK(ranges <= 2);  // and the one above: nothing below, beside, or behind in a grid one cell deep
  }
  for (const std::string& name : variant_names()) {
    INFO(name);
    const Kernels& kernels = kernels_named(name);
    grid.reserve(3, 8, kernels.list_lanes);
    kernels.build_lists(grid.build_view(sorted.data(), 3), 0, 3);
    for (std::uint32_t i = 0; i < 3; ++i)
      CHECK(grid.counts()[i] == (std::isnan(sorted[i].y) ? 0u : 1u));  // the two real balls touch
  }
}
