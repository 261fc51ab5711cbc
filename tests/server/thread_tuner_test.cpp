// The paced server's thread tuner steps with whichever thread count its
// running estimates find cheaper, and follows a change of load within about
// half a second.

#include "server/thread_tuner.h"

#include <catch2/catch.hpp>

using fishtank::ThreadTuner;

namespace {

struct Run {
  double now = 0.0;
  int batches = 0, with_one = 0;  // batches fed, and of those stepped on one thread
};

// Feeds the tuner 4 ms batches of 5 steps from `from` until `until`, each
// costing seconds_per_step(threads in use) per step.
template <class Cost>
Run run(ThreadTuner& tuner, double from, double until, Cost seconds_per_step) {
  Run r{from};
  for (; r.now < until; r.now += 0.004) {
    ++r.batches;
    r.with_one += tuner.threads() == 1;
    tuner.record(5 * seconds_per_step(tuner.threads()), 5, r.now);
  }
  return r;
}

// Seconds after `from` until the tuner has chosen `threads`, at most `limit`.
template <class Cost>
double time_to_choose(ThreadTuner& tuner, int threads, double from, double limit, Cost seconds_per_step) {
  double now = from;
  for (; now < from + limit && tuner.chosen() != threads; now += 0.004)
    tuner.record(5 * seconds_per_step(tuner.threads()), 5, now);
  return now - from;
}

}  // namespace

TEST_CASE("the tuner keeps one thread when one thread steps faster", "[server][threads]") {
  ThreadTuner tuner(2);
  CHECK(tuner.threads() == 2);  // starts with every thread
  const auto cost = [](int threads) { return threads == 1 ? 150e-6 : 170e-6; };
  run(tuner, 0.0, 0.5, cost);
  CHECK(tuner.chosen() == 1);
  // From then on the other count is only probed: a millisecond of steps every kProbeSeconds or so.
  const Run r = run(tuner, 0.5, 2.5, cost);
  CHECK(tuner.chosen() == 1);
  CHECK(r.batches - r.with_one < r.batches / 8);
}

TEST_CASE("the tuner keeps every thread when they step faster", "[server][threads]") {
  ThreadTuner tuner(4);
  const Run r = run(tuner, 0.0, 2.0, [](int threads) { return threads == 1 ? 190e-6 : 60e-6; });
  CHECK(tuner.chosen() == 4);
  CHECK(r.with_one > 0);
  CHECK(r.with_one < r.batches / 8);
}

TEST_CASE("a count that stalls is probed less often", "[server][threads]") {
  // Every thread five times dearer than one (a machine crowded with busy processes).
  ThreadTuner tuner(2);
  run(tuner, 0.0, 0.5, [](int threads) { return threads == 1 ? 100e-6 : 500e-6; });
  const Run r = run(tuner, 0.5, 4.5, [](int threads) { return threads == 1 ? 100e-6 : 500e-6; });
  CHECK(tuner.chosen() == 1);
  // One 4 ms batch every kProbeSeconds * kMaxProbeBackoff: 8 probes in 4 s.
  CHECK(r.batches - r.with_one <= 10);
}

TEST_CASE("the tuner follows a change of load within about half a second", "[server][threads]") {
  ThreadTuner tuner(2);
  const auto idle = [](int threads) { return threads == 1 ? 100e-6 : 120e-6; };
  const auto loaded = [](int threads) { return threads == 1 ? 400e-6 : 220e-6; };
  double now = run(tuner, 0.0, 2.0, idle).now;
  REQUIRE(tuner.chosen() == 1);
  const double to_all = time_to_choose(tuner, 2, now, 5.0, loaded);
  CHECK(to_all <= 0.6);
  now += to_all;
  now = run(tuner, now, now + 2.0, loaded).now;
  REQUIRE(tuner.chosen() == 2);
  CHECK(time_to_choose(tuner, 1, now, 5.0, idle) <= 0.6);
}

TEST_CASE("two nearly equal counts do not swap back and forth", "[server][threads]") {
  ThreadTuner tuner(2);
  int swaps = 0, last = tuner.chosen();
  // Within 2 % of each other, alternating which is cheaper every 50 ms.
  for (double now = 0.0; now < 5.0; now += 0.004) {
    const bool even = static_cast<int>(now / 0.05) % 2 == 0;
    const double one = even ? 100e-6 : 102e-6, all = even ? 102e-6 : 100e-6;
    tuner.record(5 * (tuner.threads() == 1 ? one : all), 5, now);
    swaps += tuner.chosen() != last;
    last = tuner.chosen();
  }
  CHECK(swaps <= 1);
}

TEST_CASE("a single-threaded pool is left alone", "[server][threads]") {
  ThreadTuner tuner(1);
  const Run r = run(tuner, 0.0, 30.0, [](int) { return 100e-6; });
  CHECK(tuner.threads() == 1);
  CHECK(r.with_one == r.batches);
}

TEST_CASE("while the machine's load decides, the tuner steps with its count unprobed, then probes the other at once",
          "[server][threads]") {
  using Load = ThreadTuner::Load;
  ThreadTuner tuner(2);
  const auto cost = [](int threads) { return threads == 1 ? 200e-6 : 100e-6; };  // every thread cheaper
  double now = run(tuner, 0.0, 1.0, cost).now;
  REQUIRE(tuner.chosen() == 2);
  int with_all = 0;
  for (double until = now + 2.0; now < until; now += 0.004) {
    with_all += tuner.threads() != 1;
    tuner.record(5 * cost(tuner.threads()), 5, now, Load::kOneThread);
  }
  CHECK(tuner.chosen() == 1);
  CHECK(with_all <= 1);  // the batch that met the crowd
  tuner.record(5 * cost(tuner.threads()), 5, now);
  CHECK(tuner.threads() == 2);  // the first batch measuring again probes every thread
  CHECK(time_to_choose(tuner, 2, now, 5.0, cost) <= 0.1);
  // Every thread decided by the load, though one is cheaper by the clock: no probe of one.
  const auto dearer = [](int threads) { return threads == 1 ? 100e-6 : 200e-6; };
  int with_one = 0;
  for (double until = now + 2.0; now < until; now += 0.004) {
    with_one += tuner.threads() == 1;
    tuner.record(5 * dearer(tuner.threads()), 5, now, Load::kEveryThread);
  }
  CHECK(tuner.chosen() == 2);
  CHECK(with_one == 0);
}
