// The placement probe the benchmarks print: a cache line's trip between two
// CPUs is timed as a plausible positive time between two distinct CPUs the
// process may use, and not at all where it has fewer than two.

#include "server/bench/line_transfer.h"

#include <sched.h>

#include <catch2/catch.hpp>

using namespace fishtank;

TEST_CASE("a cache line's trip between the first two CPUs is timed, or not where there is one", "[bench]") {
  cpu_set_t allowed;
  REQUIRE(sched_getaffinity(0, sizeof allowed, &allowed) == 0);
  const std::optional<LineTransfer> t = time_line_transfer(2000);
  if (CPU_COUNT(&allowed) < 2) {
    CHECK(!t);
    return;
  }
  REQUIRE(t);
  CHECK(t->cpu_a != t->cpu_b);
  CHECK(CPU_ISSET(t->cpu_a, &allowed));
  CHECK(CPU_ISSET(t->cpu_b, &allowed));
  // A trip takes some nanoseconds; a mean of a millisecond would mean the
  // threads waited for the CPUs, not for the line.
  CHECK(t->ns > 1.0);
  CHECK(t->ns < 1e6);
}

TEST_CASE("no round trips time nothing", "[bench]") { CHECK(!time_line_transfer(0)); }
