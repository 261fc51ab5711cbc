// Results do not depend on the number of worker threads: every ball's force
// is summed by one thread in a fixed order, so the state is bit-identical
// for 1, 2 and 4 threads (compared through a hash of every position and
// velocity, as Box2D does).

#include <catch2/catch.hpp>
#include <cstring>
#include <numeric>
#include <random>
#include <vector>

#include "tests/physics/scenarios.h"

using namespace fishtank;

namespace {

std::uint64_t run(const Kernels& kernels, int threads) {
  // 5000 balls, so that even 4 threads each get a chunk worth splitting off.
  PhysicsParams params;
  params.tank.min = {-40.0f, 0.0f, -40.0f};
  params.tank.max = {40.0f, 40.0f, 40.0f};
  World world(params, kernels, threads, 99);
  for (int b = 0; b < 5000; ++b) {
    Vec3 p{-39.0f + 3.05f * (b % 26), 1.6f + 3.05f * (b / 676), -39.0f + 3.05f * ((b / 26) % 26)};
    world.place_ball(b % kKindCount, p, Vec3{0.1f * (b % 7) - 0.3f, 0.0f, 0.1f * (b % 5) - 0.2f});
  }
  const std::uint32_t player = world.add_player();
  world.set_player_velocity(player, {3.0f, -4.0f, 1.0f});
  for (int s = 0; s < 1500; ++s) {
    if (s == 750) world.set_player_velocity(player, {-6.0f, 2.0f, 0.0f});
    world.step();
  }
  REQUIRE(world.threads() == threads);
  REQUIRE(world.escaped_or_invalid() == 0);
  return world.state_hash();
}

}  // namespace

TEST_CASE("state is bit-identical for 1, 2 and 4 threads", "[physics][determinism]") {
  const std::uint64_t one = run(kSseKernels, 1);
  CHECK(run(kSseKernels, 2) == one);
  CHECK(run(kSseKernels, 4) == one);
}

TEST_CASE("the AVX2 level's state is bit-identical for 1, 2 and 3 threads", "[physics][determinism]") {
  if (!cpu_has_avx2()) {
    WARN("this processor has no AVX2; nothing to compare");
    return;
  }
  // The AVX2 kernel carries eight balls per vector and sums with fused
  // multiply-adds; three threads give chunks of unequal lengths (chunks start
  // at multiples of the 64-ball step batch).
  const std::uint64_t one = run(kAvx2Kernels, 1);
  CHECK(run(kAvx2Kernels, 2) == one);
  CHECK(run(kAvx2Kernels, 3) == one);
}

namespace {

// One step of n densely packed random balls of every kind (many in contact),
// by a kernel called on the given consecutive ranges of balls; returns every
// output value's bits.
std::vector<std::uint32_t> step_in_ranges(const Kernels& kernels, const std::vector<std::uint32_t>& bounds) {
  const std::uint32_t n = bounds.back();
  PhysicsParams params;
  params.tank.min = {-6.0f, 0.0f, -6.0f};
  params.tank.max = {6.0f, 12.0f, 6.0f};
  const ContactModel model = make_contact_model(params);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> at(-5.0f, 5.0f), speed(-1.0f, 1.0f);
  AlignedVector<Float4> unsorted(n + kGhostSlots, kGhostPos), vel_half(n + kGhostSlots, Float4{0, 0, 0, 1});
  for (std::uint32_t i = 0; i < n; ++i) {
    const BallKind& kind = kBallKinds[i % kKindCount];
    unsorted[i] = {at(rng), 6.0f + at(rng), at(rng), 0.5f * kind.diameter};
    vel_half[i] = {speed(rng), speed(rng), speed(rng), kind.mass};
  }
  NeighbourList list;
  list.configure(params.tank, params.skin);
  std::vector<std::uint32_t> order;
  list.sort(unsorted.data(), n, order);
  AlignedVector<Float4> pos(unsorted);  // cell order, as the world keeps it
  for (std::uint32_t k = 0; k < n; ++k) pos[k] = unsorted[order[k]];
  list.reserve(n, 64);
  REQUIRE(kernels.build_lists(list.build_view(pos.data(), n), 0, n) <= list.stride());
  const std::uint32_t listed = std::accumulate(list.counts(), list.counts() + n, 0u);
  REQUIRE(listed > 4 * n);  // dense: most balls have several neighbours, of different counts

  AlignedVector<Float4> vel(n), pos_next(n), vel_half_next(n);
  const StepArrays s{pos.data(),
                     vel_half.data(),
                     vel.data(),
                     pos_next.data(),
                     vel_half_next.data(),
                     pos.data(),
                     list.neighbours(),
                     list.counts(),
                     list.stride(),
                     list.batch_order(),
                     nullptr,
                     nullptr,
                     0};
  for (std::size_t r = 0; r + 1 < bounds.size(); ++r) kernels.step(s, model, bounds[r], bounds[r + 1]);
  std::vector<std::uint32_t> bits;
  for (const AlignedVector<Float4>* out : {&vel, &pos_next, &vel_half_next})
    for (const Float4& f : *out)
      for (float x : {f.x, f.y, f.z, f.w}) {
        std::uint32_t b;
        std::memcpy(&b, &x, sizeof b);
        bits.push_back(b);
      }
  return bits;
}

}  // namespace

TEST_CASE("a ball's step does not depend on which balls share its vector", "[physics][determinism]") {
  // Ranges that start at odd balls and cut batches short: each SIMD kernel then
  // sorts those batches itself and groups other balls in its vectors than
  // when it steps all 300 at once.
  std::vector<const Kernels*> simd{&kSseKernels};
  if (cpu_has_avx2()) simd.push_back(&kAvx2Kernels);
  for (const Kernels* kernels : simd) {
    INFO(kernels->variant);
    const std::vector<std::uint32_t> whole = step_in_ranges(*kernels, {0, 300});
    CHECK(step_in_ranges(*kernels, {0, 1, 4, 101, 300}) == whole);
    CHECK(step_in_ranges(*kernels, {0, 37, 64, 299, 300}) == whole);
  }
}
