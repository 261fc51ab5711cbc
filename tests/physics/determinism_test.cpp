// Results do not depend on the number of worker threads: every ball's force
// is summed by one thread in a fixed order, so the state is bit-identical
// for 1, 2 and 4 threads (compared through a hash of every position and
// velocity, and pinned to one expected hash, as Box2D's test_determinism does).

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstring>
#include <numeric>
#include <random>
#include <thread>
#include <vector>

#include "server/physics/prefetch_plan.h"
#include "server/physics/world_measures.h"
#include "tests/physics/scenarios.h"

using namespace fishtank;

namespace {

// `hook` runs on each worker thread as it picks up a pass, and `at_step`
// before each step (to stall a worker on purpose).
std::uint64_t run(const Kernels& kernels, int threads, std::function<void(int)> hook = {},
                  std::function<void(int)> at_step = {}) {
  // 5000 balls, so that even 4 threads each get a chunk worth splitting off.
  PhysicsParams params;
  params.tank.min = {-40.0f, 0.0f, -40.0f};
  params.tank.max = {40.0f, 40.0f, 40.0f};
  World world(params, kernels, threads, 99);
  if (hook) world.set_worker_hook(std::move(hook));
  for (int b = 0; b < 5000; ++b) {
    Vec3 p{-39.0f + 3.05f * (b % 26), 1.6f + 3.05f * (b / 676), -39.0f + 3.05f * ((b / 26) % 26)};
    world.place_ball(b % kKindCount, p, Vec3{0.1f * (b % 7) - 0.3f, 0.0f, 0.1f * (b % 5) - 0.2f});
  }
  const std::uint32_t player = world.add_player();
  world.set_player_velocity(player, {3.0f, -4.0f, 1.0f});
  for (int s = 0; s < 1500; ++s) {
    if (s == 750) world.set_player_velocity(player, {-6.0f, 2.0f, 0.0f});
    if (at_step) at_step(s);
    world.step();
  }
  REQUIRE(world.threads() == threads);
  REQUIRE(escaped_or_invalid(world) == 0);
  return state_hash(world);
}

}  // namespace

// The scalar twin's state after run(): plain IEEE float arithmetic, with no
// estimate and no fused multiply-add, is the same on every x86-64 processor.
// Only a change meant to change results may change it.
constexpr std::uint64_t kScalarStateHash = 0xc06efbe53c4fe7bdull;

TEST_CASE("state is bit-identical for 1, 2 and 4 threads", "[physics][determinism]") {
  Kernels threaded_scalar = kScalarKernels;  // the product steps the scalar twin on one thread
  threaded_scalar.threaded = true;
  for (int threads : {1, 2, 4}) CHECK(run(threaded_scalar, threads) == kScalarStateHash);
  // Compared, not pinned: rsqrtps's estimate differs between processor makers.
  const std::uint64_t one = run(kSseKernels, 1);
  CHECK(run(kSseKernels, 2) == one);
  CHECK(run(kSseKernels, 4) == one);
}

TEST_CASE("a stalled worker holds up no step and changes nothing", "[physics][determinism]") {
  using Clock = std::chrono::steady_clock;
  const std::uint64_t one = run(kSseKernels, 1);
  // Worker 1 is held back a little on every fifth pass it picks up, so the
  // caller takes its chunks in ever-changing order, and for steps 300-399 it
  // is held outright (up to 5 s a pass, were the step to wait for it).
  std::atomic<int> passes{0};
  std::atomic<bool> held{false};
  Clock::time_point held_from, held_to;
  const auto hook = [&](int thread) {
    if (thread != 1) return;
    if (passes.fetch_add(1) % 5 == 0) std::this_thread::sleep_for(std::chrono::microseconds(300));
    const Clock::time_point give_up = Clock::now() + std::chrono::seconds(5);
    while (held.load() && Clock::now() < give_up) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  };
  const auto at_step = [&](int s) {
    if (s == 300) held = true, held_from = Clock::now();
    if (s == 400) held = false, held_to = Clock::now();
  };
  CHECK(run(kSseKernels, 2, hook, at_step) == one);
  CHECK(passes > 0);
  // A hundred steps while the worker was held: had any waited for it, 5 s or more.
  CHECK(std::chrono::duration<double>(held_to - held_from).count() < 4.0);
}

TEST_CASE("the AVX2 level's state is bit-identical for 1, 2 and 3 threads", "[physics][determinism]") {
  if (!cpu_has_avx2()) {
    WARN("SKIPPED: this processor has no AVX2; nothing to compare");
    return;
  }
  // The AVX2 kernel carries eight balls per vector and sums with fused
  // multiply-adds; three threads give chunks of unequal lengths (chunks start
  // at multiples of the step batch, kStepBatch).
  const std::uint64_t one = run(kAvx2Kernels, 1);
  CHECK(run(kAvx2Kernels, 2) == one);
  CHECK(run(kAvx2Kernels, 3) == one);
}

namespace {

struct WideRun {
  std::uint64_t hash;
  std::uint32_t remote_lines;  // lines of rows the last build noted as remote (RemoteRows)
};

// 40 000 balls in a flat tank 63 cells wide, four column blocks: past the
// default balls from which the world's step asks for rows ahead
// (PhysicsParams::prefetch_from), for the rows at the chunks' edges and for
// the rows across the blocks' faces.
WideRun run_wide(int threads, std::uint32_t prefetch_from = PhysicsParams{}.prefetch_from,
                 const Kernels& kernels = kSseKernels) {
  PhysicsParams params;
  params.prefetch_from = prefetch_from;
  params.tank.min = {-101.0f, 0.0f, -101.0f};
  params.tank.max = {101.0f, 32.0f, 101.0f};
  World world(params, kernels, threads, 99);
  constexpr int kSide = 66;
  for (int b = 0; b < 40000; ++b) {
    Vec3 p{-100.0f + 3.05f * (b % kSide), 1.6f + 3.05f * (b / (kSide * kSide)),
           -100.0f + 3.05f * ((b / kSide) % kSide)};
    world.place_ball(b % kKindCount, p, Vec3{0.5f * (b % 7) - 1.5f, 0.0f, 0.5f * (b % 5) - 1.0f});
  }
  for (int s = 0; s < 200; ++s) world.step();
  REQUIRE(escaped_or_invalid(world) == 0);
  REQUIRE(world.rebuilds() > 1);
  WideRun out{state_hash(world), 0};
  for (std::uint32_t b = 0; b < (world.ball_count() + kStepBatch - 1) / kStepBatch; ++b)
    out.remote_lines += world.neighbour_list().remote_rows()[b].count;
  return out;
}

}  // namespace

TEST_CASE("a pile beyond the caches is bit-identical for 1 and 2 threads, its remote rows asked for ahead or not",
          "[physics][determinism]") {
  const WideRun one = run_wide(1), two = run_wide(2);
  CHECK(two.hash == one.hash);
  CHECK(one.remote_lines > 0);  // the builds noted rows across the blocks' faces for the step
  CHECK(two.remote_lines == one.remote_lines);
  // Asking ahead changes speed only: never asking leaves every position and velocity as it was.
  const WideRun unasked = run_wide(2, 1'000'000'000);
  CHECK(unasked.hash == one.hash);
  CHECK(unasked.remote_lines == 0);  // nothing noted for a step that asks for nothing
  if (cpu_has_avx2()) {
    INFO("AVX2");
    CHECK(run_wide(2, 1'000'000'000, kAvx2Kernels).hash == run_wide(2, 0, kAvx2Kernels).hash);
  }
}

namespace {

// n densely packed random balls of every kind (many in contact), in cell
// order, with their lists as a kernel set builds them.
struct DenseScene {
  ContactModel model;
  TankBounds tank;
  AlignedVector<Float4> pos, vel_half, vel_half_before;
  NeighbourList list;
  std::uint32_t n;

  DenseScene(const Kernels& kernels, std::uint32_t balls) : n(balls) {
    PhysicsParams params;
    params.tank.min = {-6.0f, 0.0f, -6.0f};
    params.tank.max = {6.0f, 12.0f, 6.0f};
    model = make_contact_model(params);
    tank = params.tank;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> at(-5.0f, 5.0f), speed(-1.0f, 1.0f);
    AlignedVector<Float4> unsorted(n + kGhostSlots, kGhostPos), unsorted_vel(n + kGhostSlots, Float4{0, 0, 0, 1});
    for (std::uint32_t i = 0; i < n; ++i) {
      const BallKind& kind = kBallKinds[i % kKindCount];
      unsorted[i] = {at(rng), 6.0f + at(rng), at(rng), 0.5f * kind.diameter};
      unsorted_vel[i] = {speed(rng), speed(rng), speed(rng), 1.0f / kind.mass};  // a half-step row: 1 / mass
    }
    list.configure(params.tank, starting_skin(params));
    std::vector<std::uint32_t> order;
    list.sort(unsorted.data(), n, order);
    pos = unsorted;
    vel_half = unsorted_vel;
    for (std::uint32_t k = 0; k < n; ++k) pos[k] = unsorted[order[k]], vel_half[k] = unsorted_vel[order[k]];
    // Last accelerations of either sign, which contacts that start or end read.
    vel_half_before = vel_half;
    for (std::uint32_t k = 0; k < n; ++k)
      for (float* v : {&vel_half_before[k].x, &vel_half_before[k].y, &vel_half_before[k].z})
        *v -= 50.0f * speed(rng) * model.dt;
    list.reserve(n, 64, kernels.list_lanes);
    REQUIRE(kernels.build_lists(list.build_view(pos.data(), n), 0, n) <= list.stride());
    const std::uint32_t listed = std::accumulate(list.counts(), list.counts() + n, 0u);
    REQUIRE(listed > 4 * n);  // dense: most balls have several neighbours, of different counts
  }

  // One step by the kernel, called on the given consecutive ranges of balls,
  // with the lists laid out as `layout` says; returns every output value's bits.
  std::vector<std::uint32_t> step_bits(const Kernels& kernels, const std::vector<std::uint32_t>& bounds,
                                       const GroupLists& layout) const {
    AlignedVector<Float4> pos_next(n), vel_half_next(n);
    StepContext ctx;
    StepArrays& s = ctx.arrays;
    s.pos = pos.data();
    s.vel_half = vel_half.data();
    s.vel_half_before = vel_half_before.data();
    s.pos_next = pos_next.data();
    s.vel_half_next = vel_half_next.data();
    s.lists = layout;
    s.tank = tank;
    ctx.plan = prefetch_plan(list, n, false);  // each range asks for its edge rows, as a world's chunks do
    ctx.model = model;
    for (std::size_t r = 0; r + 1 < bounds.size(); ++r) kernels.step(ctx, bounds[r], bounds[r + 1]);
    std::vector<std::uint32_t> bits;
    for (const AlignedVector<Float4>* out : {&pos_next, &vel_half_next})
      for (const Float4& f : *out)
        for (float x : {f.x, f.y, f.z, f.w}) {
          std::uint32_t b;
          std::memcpy(&b, &x, sizeof b);
          bits.push_back(b);
        }
    return bits;
  }
};

// The scene's lists laid out again (broadphase.h) with each batch's balls
// shuffled before grouping, so that every ball shares its vector with other
// balls than in the build's grouping by count.
struct Layout {
  std::vector<std::uint32_t> neighbours;
  AlignedVector<std::uint32_t> group_records;
  std::vector<std::uint32_t> group_blocks;
  GroupLists view(std::uint32_t stride) const {
    return {neighbours.data(), stride, group_records.data(), group_blocks.data()};
  }
};

Layout shuffled_groups(const DenseScene& scene, std::uint32_t lanes) {
  const std::uint32_t n = scene.n;
  std::vector<std::vector<std::uint32_t>> lists(n);
  scene.list.for_each_list([&](std::uint32_t i, ListView l) {
    for (std::uint32_t k = 0; k < l.count; ++k) lists[i].push_back(l[k]);
  });
  Layout out;
  out.neighbours.assign((std::size_t(n) + lanes - 1) * scene.list.stride(), 0);
  std::vector<std::uint32_t> batch_order(std::size_t(n) + lanes - 1);
  out.group_records.assign(4 * (std::size_t(n) + lanes - 1), 0);
  out.group_blocks.assign((std::size_t(n) + lanes - 1) / lanes, 0);
  std::mt19937 rng(3);
  for (std::uint32_t batch = 0; batch < n; batch += kStepBatch) {
    const std::uint32_t balls = batch_end(batch, n) - batch, grouped = grouped_length(balls, lanes);
    std::uint32_t* order = batch_order.data() + batch;
    std::iota(order, order + balls, batch);
    std::shuffle(order, order + balls, rng);
    for (std::uint32_t k = balls; k < grouped; ++k) order[k] = order[k - 1];
    std::uint32_t* block = out.neighbours.data() + std::size_t(batch) * scene.list.stride();
    for (std::uint32_t g = 0; g < grouped; g += lanes) {
      std::size_t blocks = 0;
      for (std::uint32_t l = 0; l < lanes; ++l) blocks = std::max(blocks, lists[order[g + l]].size());
      write_group_record(scene.pos.data(), order + g, lanes, out.group_records.data() + 4 * (std::size_t(batch) + g));
      out.group_blocks[(batch + g) / lanes] = static_cast<std::uint32_t>(blocks);
      for (std::size_t b = 0; b < blocks; ++b)
        for (std::uint32_t l = 0; l < lanes; ++l) {
          const std::vector<std::uint32_t>& list = lists[order[g + l]];
          *block++ = list_entry(b < list.size() ? list[b] : n);  // the ghost past a list's end
        }
    }
  }
  return out;
}

}  // namespace

TEST_CASE("a ball's step does not depend on which balls share its vector", "[physics][determinism]") {
  // Each SIMD kernel groups balls of similar list lengths and contacts, one per lane;
  // the same lists grouped at random, and the step called on chunks of
  // batches as the worker threads call it, must give every ball the same bits.
  std::vector<const Kernels*> simd{&kSseKernels};
  if (cpu_has_avx2()) simd.push_back(&kAvx2Kernels);
  for (const Kernels* kernels : simd) {
    INFO(kernels->variant);
    const DenseScene scene(*kernels, 300);
    const GroupLists as_built = std::get<GroupLists>(scene.list.step_lists(scene.pos.data()));
    const std::vector<std::uint32_t> built = scene.step_bits(*kernels, {0, 300}, as_built);
    CHECK(scene.step_bits(*kernels, {0, kStepBatch, 2 * kStepBatch, 300}, as_built) == built);
    const Layout shuffled = shuffled_groups(scene, kernels->list_lanes);
    CHECK(scene.step_bits(*kernels, {0, 300}, shuffled.view(scene.list.stride())) == built);
  }
}
