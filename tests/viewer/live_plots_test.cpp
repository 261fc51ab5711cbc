// The live plots keep one sample per snapshot over the last 30 s, oldest
// first, and a snapshot seen again (the same frame drawn twice) adds nothing.

#include "viewer/live_plots.h"

#include <catch2/catch.hpp>

using namespace fishtank::viewer;

namespace {
Snapshot at(double received, std::uint64_t tick, std::uint32_t contacts) {
  Snapshot s;
  s.received = received;
  s.tick = tick;
  s.contacts = contacts;
  s.kinetic_energy_per_ball = 0.5f;
  s.steps_per_s = 1400.0f;
  s.time_scale = 1.0f;
  return s;
}
}  // namespace

TEST_CASE("the plots hold the last 30 s of snapshots, oldest first, each once") {
  LivePlots plots;
  for (int i = 0; i <= 40; ++i) {
    const Snapshot s = at(i, static_cast<std::uint64_t>(i), static_cast<std::uint32_t>(100 + i));
    plots.add(s);
    plots.add(s);  // drawn twice between snapshots
  }
  const std::vector<float> contacts = plots.series(LivePlots::contacts);
  REQUIRE(contacts.size() == 31);  // seconds 10 .. 40
  CHECK(contacts.front() == 110.0f);
  CHECK(contacts.back() == 140.0f);
  CHECK(plots.span_seconds() == Approx(30.0));
  CHECK(plots.newest(LivePlots::steps_per_s) == 1400.0f);
}
