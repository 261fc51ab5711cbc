// The worker pool hands every item to exactly one thread, in chunks that
// start at multiples of its granule (of any length for costly items), and
// run_and_balance() moves the split towards chunks that take equal time when
// the threads run at different speeds (a slow core of a virtual machine).

#include "server/physics/worker_pool.h"

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <memory>
#include <vector>

using namespace fishtank;

namespace {

// Waits until `until`, polling: a thread "computes" for as long as its items
// say, whatever else the machine runs, so the speeds the pool measures are
// the ones the test sets.
void busy_until(std::chrono::steady_clock::time_point until) {
  while (std::chrono::steady_clock::now() < until) {
  }
}

}  // namespace

TEST_CASE("every item goes to exactly one thread, in chunks starting at multiples of the granule", "[pool]") {
  constexpr std::uint32_t kGranule = 128;
  enum class Run { kPlain, kBalanced, kCostly };
  for (int threads : {1, 2, 4}) {
    WorkerPool pool(threads, kGranule);
    for (std::uint32_t count : {0u, 7u, 100u, 4096u, 10000u, 12345u}) {
      for (Run run : {Run::kPlain, Run::kBalanced, Run::kCostly}) {
        std::unique_ptr<std::atomic<int>[]> seen(new std::atomic<int>[count]());
        std::atomic<bool> misaligned{false};
        std::atomic<int> chunks{0};
        const WorkerPool::Phase phase = [&](std::uint32_t begin, std::uint32_t end, int) {
          if (begin % kGranule != 0) misaligned = true;
          ++chunks;
          for (std::uint32_t i = begin; i < end; ++i) seen[i].fetch_add(1);
        };
        if (run == Run::kPlain) pool.run(count, phase);
        if (run == Run::kBalanced) pool.run_and_balance(count, phase);
        if (run == Run::kCostly) pool.run_costly(count, 3, phase);
        INFO(threads << " threads, " << count << " items, run " << int(run));
        CHECK(std::all_of(seen.get(), seen.get() + count, [](const std::atomic<int>& s) { return s == 1; }));
        if (run != Run::kCostly) CHECK_FALSE(misaligned);
        // Costly items are split from three per thread, whatever the granule.
        if (run == Run::kCostly && count > 0) CHECK(chunks == std::min<int>(threads, std::max<int>(1, count / 3)));
      }
    }
  }
}

TEST_CASE("balanced runs give a thread three times slower a quarter of the items", "[pool]") {
  // Thread 1 takes 15 us per item, thread 0 5 us: equal time means 3 : 1.
  // Chunks of 10-30 ms, so that another process taking a core for a few
  // milliseconds (ctest runs tests side by side) moves a share only a little.
  constexpr std::uint32_t kItems = 4096;
  WorkerPool pool(2, 64);
  REQUIRE(pool.shares(2) == std::vector<double>{0.5, 0.5});
  const WorkerPool::Phase phase = [](std::uint32_t begin, std::uint32_t end, int thread) {
    const auto per_item = std::chrono::microseconds(thread == 1 ? 15 : 5);
    busy_until(std::chrono::steady_clock::now() + per_item * (end - begin));
  };
  pool.run(kItems, phase);  // untimed runs leave the split alone
  REQUIRE(pool.shares(2) == std::vector<double>{0.5, 0.5});
  // Thread 1's share over the last 15 of 40 runs, by its median: one run in
  // which the machine stalled a thread moves a share for a few runs only.
  const auto settled_share = [&](const WorkerPool::Phase& p) {
    std::vector<double> last;
    for (int run = 0; run < 40; ++run) {
      pool.run_and_balance(kItems, p);
      if (run >= 25) last.push_back(pool.shares(2)[1]);
    }
    std::nth_element(last.begin(), last.begin() + last.size() / 2, last.end());
    return last[last.size() / 2];
  };
  const double slow_share = settled_share(phase);
  INFO("thread 1's share " << slow_share);
  CHECK(slow_share == Approx(0.25).margin(0.06));
  CHECK(pool.shares(2)[0] + pool.shares(2)[1] == Approx(1.0));

  // When the threads become equal again, so does the split.
  const WorkerPool::Phase equal = [](std::uint32_t begin, std::uint32_t end, int) {
    busy_until(std::chrono::steady_clock::now() + std::chrono::microseconds(5) * (end - begin));
  };
  CHECK(settled_share(equal) == Approx(0.5).margin(0.06));
}
