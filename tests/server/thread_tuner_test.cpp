// The paced server's thread tuner keeps whichever thread count measured the
// cheaper step, and measures both again after kRemeasureSeconds.

#include "server/thread_tuner.h"

#include <catch2/catch.hpp>

using fishtank::ThreadTuner;

namespace {

// Feeds the tuner 1 ms batches of 5 steps until `until`, each costing
// seconds_per_step(threads in use) per step. Returns the wall clock reached.
template <class Cost>
double run(ThreadTuner& tuner, double from, double until, Cost seconds_per_step) {
  double now = from;
  for (; now < until; now += 0.001) tuner.record(5 * seconds_per_step(tuner.threads()), 5, now);
  return now;
}

}  // namespace

TEST_CASE("the tuner keeps one thread when one thread steps faster", "[server][threads]") {
  ThreadTuner tuner(2);
  CHECK(tuner.threads() == 2);  // starts by timing every thread
  run(tuner, 0.0, 2.0, [](int threads) { return threads == 1 ? 150e-6 : 170e-6; });
  CHECK(tuner.threads() == 1);
}

TEST_CASE("the tuner keeps every thread when they step faster", "[server][threads]") {
  ThreadTuner tuner(4);
  run(tuner, 0.0, 2.0, [](int threads) { return threads == 1 ? 190e-6 : 60e-6; });
  CHECK(tuner.threads() == 4);
}

TEST_CASE("the tuner measures again when the world changes", "[server][threads]") {
  ThreadTuner tuner(2);
  // A small world first: one thread wins.
  double now = run(tuner, 0.0, 2.0, [](int threads) { return threads == 1 ? 100e-6 : 120e-6; });
  REQUIRE(tuner.threads() == 1);
  // Then the tank fills and two threads would be faster: after the next
  // measurement, at most kRemeasureSeconds plus two windows later, it switches.
  const auto busy = [](int threads) { return threads == 1 ? 400e-6 : 220e-6; };
  now = run(tuner, now, now + ThreadTuner::kRemeasureSeconds + 3 * ThreadTuner::kWindowSeconds, busy);
  CHECK(tuner.threads() == 2);
}

TEST_CASE("a single-threaded pool is left alone", "[server][threads]") {
  ThreadTuner tuner(1);
  run(tuner, 0.0, 30.0, [](int) { return 100e-6; });
  CHECK(tuner.threads() == 1);
}
