// The worker pool hands every item to exactly one thread, in chunks that
// start at multiples of its granule (of any length for costly items), and a
// thread that is stalled or slow never holds up a run beyond the chunk it is
// inside: the other threads take the chunks it has not started. Its default
// size is the cores the process may run on.

#include "server/physics/worker_pool.h"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <memory>
#include <thread>
#include <vector>

using namespace fishtank;
using Clock = std::chrono::steady_clock;

namespace {

// Waits until `until`, polling: a thread "computes" for as long as its items
// say, whatever else the machine runs.
void busy_until(Clock::time_point until) {
  while (Clock::now() < until) {
  }
}

// Holds worker thread 1 in the pool's hook while `stalled` is set (at most
// `limit`), as if the OS had not scheduled it.
struct Stall {
  std::atomic<bool> stalled{false};
  std::atomic<int> held{0};  // times the hook held the thread
  std::chrono::milliseconds limit{5000};
  void operator()(int thread) {
    if (thread != 1 || !stalled.load()) return;
    ++held;
    const Clock::time_point give_up = Clock::now() + limit;
    while (stalled.load() && Clock::now() < give_up) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
};

}  // namespace

TEST_CASE("every item goes to exactly one thread, in chunks starting at multiples of the granule", "[pool]") {
  constexpr std::uint32_t kGranule = 128;
  for (int threads : {1, 2, 4}) {
    WorkerPool pool(threads, kGranule);
    for (std::uint32_t count : {0u, 7u, 100u, 4096u, 10000u, 12345u}) {
      for (bool costly : {false, true}) {
        std::unique_ptr<std::atomic<int>[]> seen(new std::atomic<int>[count]());
        std::vector<std::uint32_t> chunk_begin(pool.max_chunks(), ~0u);
        std::atomic<bool> misaligned{false}, bad_chunk{false};
        const WorkerPool::Phase phase = [&](std::uint32_t begin, std::uint32_t end, int chunk) {
          if (begin % kGranule != 0) misaligned = true;
          if (chunk < 0 || chunk >= pool.max_chunks())
            bad_chunk = true;
          else
            chunk_begin[chunk] = begin;
          for (std::uint32_t i = begin; i < end; ++i) seen[i].fetch_add(1);
        };
        if (costly)
          pool.run_costly(count, 3, phase);
        else
          pool.run(count, phase);
        INFO(threads << " threads, " << count << " items, " << (costly ? "costly" : "plain"));
        CHECK(std::all_of(seen.get(), seen.get() + count, [](const std::atomic<int>& s) { return s == 1; }));
        if (!costly) CHECK_FALSE(misaligned);
        REQUIRE_FALSE(bad_chunk);
        // Chunks are numbered in item order, so per-chunk results gather in item order.
        std::vector<std::uint32_t> used;
        for (std::uint32_t b : chunk_begin)
          if (b != ~0u) used.push_back(b);
        CHECK(std::is_sorted(used.begin(), used.end()));
      }
    }
  }
}

TEST_CASE("a stalled worker does not hold up a run: the caller takes its chunks", "[pool]") {
  Stall stall;
  WorkerPool pool(2, 64);
  pool.set_worker_hook([&](int thread) { stall(thread); });
  constexpr std::uint32_t kItems = 8192;
  std::vector<int> seen(kItems, 0);
  stall.stalled = true;
  const Clock::time_point start = Clock::now();
  pool.run(kItems, [&](std::uint32_t begin, std::uint32_t end, int) {
    for (std::uint32_t i = begin; i < end; ++i) ++seen[i];
  });
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  // Still stalled (the hook holds it for 5 s): the run finished without it.
  CHECK(seconds < 2.0);
  CHECK(std::all_of(seen.begin(), seen.end(), [](int s) { return s == 1; }));
  CHECK(pool.shares() == std::vector<double>{1.0, 0.0});
  stall.stalled = false;
  // Released, it takes part again in a run long enough for it to wake up.
  double worker_share = 0.0;
  for (int run = 0; run < 200 && worker_share == 0.0; ++run) {
    pool.run(kItems, [](std::uint32_t begin, std::uint32_t end, int) {
      busy_until(Clock::now() + std::chrono::microseconds(2) * (end - begin));
    });
    worker_share = pool.shares()[1];
  }
  CHECK(worker_share > 0.0);
}

TEST_CASE("a worker that picks up a phase late never runs a later phase's chunk", "[pool]") {
  // The hook delays worker 1 by 0-3 ms on each phase it picks up, while the
  // caller goes on through phases of about 0.2 ms: each must still see every
  // item once, until the worker has been late many times.
  std::atomic<int> picked_up{0};
  WorkerPool pool(2, 64);
  pool.set_worker_hook([&](int thread) {
    if (thread == 1) std::this_thread::sleep_for(std::chrono::milliseconds(picked_up.fetch_add(1) % 4));
  });
  constexpr std::uint32_t kItems = 4096;
  bool all_once = true;
  for (int phase = 0; phase < 5000 && picked_up < 40; ++phase) {
    std::unique_ptr<std::atomic<int>[]> seen(new std::atomic<int>[kItems]());
    pool.run(kItems, [&](std::uint32_t begin, std::uint32_t end, int) {
      for (std::uint32_t i = begin; i < end; ++i) seen[i].fetch_add(1);
      busy_until(Clock::now() + std::chrono::nanoseconds(50) * (end - begin));
    });
    all_once =
        all_once && std::all_of(seen.get(), seen.get() + kItems, [](const std::atomic<int>& s) { return s == 1; });
  }
  CHECK(all_once);
  CHECK(picked_up >= 40);
}

TEST_CASE("a thread three times slower computes about a quarter of the items", "[pool]") {
  // The test makes thread 1 three times slower per item than thread 0: in equal time, 1 : 3.
  constexpr std::uint32_t kItems = 4096;
  WorkerPool pool(2, 64);
  const std::thread::id caller = std::this_thread::get_id();
  const WorkerPool::Phase phase = [caller](std::uint32_t begin, std::uint32_t end, int) {
    const auto per_item = std::chrono::microseconds(std::this_thread::get_id() == caller ? 5 : 15);
    busy_until(Clock::now() + per_item * (end - begin));
  };
  // The median over runs: another process taking a core for a while moves one run only.
  std::vector<double> slow_share;
  for (int run = 0; run < 15; ++run) {
    pool.run(kItems, phase);
    slow_share.push_back(pool.shares()[1]);
  }
  std::nth_element(slow_share.begin(), slow_share.begin() + slow_share.size() / 2, slow_share.end());
  const double median = slow_share[slow_share.size() / 2];
  INFO("thread 1's share " << median);
  // Equal shares would be 0.5; in chunks of an eighth the slow thread takes 2 (0.25), or 3 (0.375)
  // when a busy machine delays the fast one.
  CHECK(median < 0.45);
  CHECK(median > 0.1);
}

namespace {
std::vector<int> cpus_of_this_thread() {
  cpu_set_t set;
  CPU_ZERO(&set);
  pthread_getaffinity_np(pthread_self(), sizeof set, &set);
  std::vector<int> cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) cpus.push_back(c);
  return cpus;
}
}  // namespace

TEST_CASE("while every thread steps, each is pinned to a CPU of its own, and below that all are free again", "[pool]") {
  const std::vector<int> allowed = cpus_of_this_thread();
  if (allowed.size() < 2) {
    WARN("SKIPPED: one CPU: the pool never pins, nothing to check");
    return;
  }
  const int threads = static_cast<int>(allowed.size());
  std::vector<std::vector<int>> seen(threads);  // each thread's CPUs as it ran a chunk
  {
    WorkerPool pool(threads, 1);
    const std::thread::id caller = std::this_thread::get_id();
    std::atomic<int> workers_seen{0};
    pool.set_worker_hook([&](int thread) {
      if (seen[thread].empty()) seen[thread] = cpus_of_this_thread(), ++workers_seen;
    });
    pool.run(threads * 4096, [&](std::uint32_t, std::uint32_t, int) {
      if (std::this_thread::get_id() == caller) seen[0] = cpus_of_this_thread();
    });
    // A worker may pick the phase up after the caller has done it all.
    const Clock::time_point give_up = Clock::now() + std::chrono::seconds(10);
    while (workers_seen.load() < threads - 1 && Clock::now() < give_up) std::this_thread::yield();
    for (int t = 0; t < threads; ++t) {
      INFO("thread " << t);
      REQUIRE(seen[t].size() == 1);
      CHECK(seen[t][0] == allowed[t]);
    }

    pool.set_active_limit(1);
    pool.run(threads * 4096, [](std::uint32_t, std::uint32_t, int) {});
    CHECK(cpus_of_this_thread() == allowed);
    pool.set_active_limit(threads);
    pool.run(threads * 4096, [](std::uint32_t, std::uint32_t, int) {});
    CHECK(cpus_of_this_thread().size() == 1);
  }
  CHECK(cpus_of_this_thread() == allowed);  // the pool gave the caller its CPUs back
}

TEST_CASE("the default thread count stays the cores this process may run on after a pool pinned its caller", "[pool]") {
  cpu_set_t all;
  REQUIRE(sched_getaffinity(0, sizeof all, &all) == 0);
  const int before = WorkerPool::hardware_threads();
  CHECK(before == CPU_COUNT(&all));
  {
    WorkerPool pool(2, 1);
    std::atomic<int> items{0};
    pool.run(64, [&](std::uint32_t begin, std::uint32_t end, int) { items += static_cast<int>(end - begin); });
    REQUIRE(items == 64);
    CHECK(WorkerPool::hardware_threads() == before);  // while the caller is pinned
  }
  CHECK(WorkerPool::hardware_threads() == before);
}
