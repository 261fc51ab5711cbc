// The headless benchmark's scenes and report: the wide scene places exactly
// the balls asked for, none overlapping; settling stops at rest (several
// checks in a row) or at its limit; the JSON report carries every figure the
// issue asks for, and they agree with each other and with the world they
// describe.

#include "server/bench/benchmark.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "server/physics/world_measures.h"

using namespace fishtank;

TEST_CASE("the wide scene places exactly N balls, none touching, in a tank widened for them", "[bench]") {
  SceneSpec spec;
  spec.name = "wide";
  spec.balls = 2000;
  PhysicsParams params;
  params.tank = scene_tank(spec);
  REQUIRE(validate(params).empty());
  CHECK(params.tank.size().y == 40.0f);
  World world(params, kScalarKernels, 1, 1);
  REQUIRE(populate(world, spec).empty());
  REQUIRE(world.ball_count() == 2000);
  const Float4* p = world.positions();
  float closest = 1e9f;  // the smallest gap between two balls' surfaces
  for (std::uint32_t i = 0; i < world.ball_count(); ++i)
    for (std::uint32_t j = i + 1; j < world.ball_count(); ++j) {
      const float dx = p[i].x - p[j].x, dy = p[i].y - p[j].y, dz = p[i].z - p[j].z;
      closest = std::min(closest, std::sqrt(dx * dx + dy * dy + dz * dz) - p[i].w - p[j].w);
    }
  CHECK(closest > 0.0f);
  CHECK(escaped_or_invalid(world) == 0);
}

TEST_CASE(
    "rest is kRestChecks checks in a row at rest: a pile that dips under the threshold and swings back is not "
    "settled",
    "[bench]") {
  RestWatch watch;
  for (int i = 1; i < kRestChecks; ++i) CHECK_FALSE(watch.settled(true));
  CHECK_FALSE(watch.settled(false));  // swung back: counting starts again
  for (int i = 1; i < kRestChecks; ++i) CHECK_FALSE(watch.settled(true));
  CHECK(watch.settled(true));
}

TEST_CASE("settle() stops at kRestChecks checks at rest, not at the first: an empty tank rests from the start",
          "[bench]") {
  SceneSpec spec;
  spec.balls = 0;
  World world(PhysicsParams{}, kSseKernels, 1, spec.seed);
  TunedStepper untuned(world, false);
  const SettleReport report = settle(untuned, spec);
  REQUIRE(report.settled);
  const double check = std::floor(0.1 / world.dt()) * world.dt();  // checks a whole number of steps apart
  CHECK(report.sim_seconds == Approx(kRestChecks * check).margin(1e-9));
}

TEST_CASE("the benchmark report holds every figure asked for, consistent with the run", "[bench]") {
  BenchSpec spec;
  spec.scene.balls = 300;
  spec.scene.max_settle_seconds = 2.0;
  spec.steps = 40;
  spec.windows = 4;
  World world(PhysicsParams{}, kSseKernels, 2, spec.scene.seed);
  REQUIRE(populate(world, spec.scene).empty());
  TunedStepper untuned(world, false);
  const SettleReport settled = settle(untuned, spec.scene);
  CHECK(settled.sim_seconds <= 2.0 + 0.11);  // stops at its limit, checked every tenth of a second
  CHECK(settled.steps == world.steps());
  REQUIRE(world.pending() == 0);

  const nlohmann::json j = time_steps(untuned, spec, settled);
  for (const char* key :
       {"variant", "simd", "threads", "balls", "steps", "seconds", "steps_per_s", "ball_steps_per_s", "dt", "k",
        "max_overlap", "pile_top", "phase_seconds", "settle", "peak_rss_mib", "crowding_cores", "prefetch_ahead"}) {
    INFO(key);
    CHECK(j.contains(key));
  }
  CHECK(j["variant"] == "sse");
  CHECK(j["prefetch_ahead"] == false);  // 300 balls: below PhysicsParams::prefetch_from
  CHECK(j["balls"] == 300);
  CHECK(j["steps"] == 40);
  CHECK(world.steps() == settled.steps + 40);
  CHECK(j["dt"].get<double>() == Approx(world.dt()));
  CHECK(j["k"].get<double>() == Approx(25000.0));
  const double seconds = j["seconds"], rate = j["ball_steps_per_s"];
  CHECK(seconds > 0.0);
  CHECK(j["steps_per_s"].get<double>() * 300.0 == Approx(rate));
  // The rate is the median window's: between the slowest and the fastest.
  const auto windows = j["window_ball_steps_per_s"].get<std::vector<double>>();
  REQUIRE(windows.size() == 4);
  CHECK(rate >= *std::min_element(windows.begin(), windows.end()));
  CHECK(rate <= *std::max_element(windows.begin(), windows.end()));
  const double phases = j["phase_seconds"]["step_pass"].get<double>() + j["phase_seconds"]["neighbours"].get<double>();
  CHECK(j["phase_seconds"]["step_pass"].get<double>() > 0.0);
  CHECK(phases <= seconds * 1.01 + 1e-4);  // the phases are parts of the timed steps
  // sort, list_build and far_checks are parts of neighbours.
  const double neighbours = j["phase_seconds"]["neighbours"], sort = j["phase_seconds"]["sort"],
               lists = j["phase_seconds"]["list_build"], checks = j["phase_seconds"]["far_checks"];
  CHECK(sort >= 0.0);
  CHECK(lists >= 0.0);
  CHECK(checks >= 0.0);
  CHECK(sort + lists + checks <= neighbours * 1.01 + 1e-6);
  // The cores' placement, timed before and after (line_transfer.h), where there are two.
  REQUIRE(j.contains("line_transfer_ns"));
  if (!j["line_transfer_ns"].is_null()) {
    CHECK(j["line_transfer_ns"]["before"].get<double>() > 0.0);
    CHECK(j["line_transfer_ns"]["after"].get<double>() > 0.0);
  }
  if (j["rebuilds"].get<int>() > 0) {  // each rebuild sorts and builds
    CHECK(sort > 0.0);
    CHECK(lists > 0.0);
  }
  CHECK(j["max_overlap"].get<double>() >= 0.0);
  CHECK(j["max_overlap"].get<double>() < 0.1);
  CHECK(j["pile_top"].get<double>() > 0.0);
  CHECK(j["pile_top"].get<double>() <= 40.0);
  CHECK(j["settle"]["settled"] == settled.settled);
}

TEST_CASE("a world of too few balls to split steps on one thread and says so, more balls on every thread", "[bench]") {
  for (const std::uint32_t balls : {2000u, 2048u}) {
    BenchSpec spec;
    spec.scene.name = "wide";
    spec.scene.balls = balls;
    spec.steps = 4;
    spec.windows = 1;
    PhysicsParams params;
    params.tank = scene_tank(spec.scene);
    World world(params, kSseKernels, 2, spec.scene.seed);
    REQUIRE(populate(world, spec.scene).empty());
    REQUIRE(world.ball_count() == balls);
    TunedStepper fixed(world, false);  // as --fixed-threads: the limit stays at both threads
    const bool split = balls >= 2048;
    INFO(balls << " balls");
    CHECK(fixed.threads() == (split ? 2 : 1));
    const nlohmann::json j = time_steps(fixed, spec, SettleReport{});
    CHECK(j["threads"] == 2);  // the pool's threads
    CHECK(j["one_thread_step_fraction"].get<double>() == (split ? 0.0 : 1.0));
    // Where the balls were too few the second thread computed nothing (where they were not, a busy machine
    // may still leave it nothing: the caller takes a late worker's chunks).
    if (!split) CHECK(j["thread_shares"][1].get<double>() == 0.0);
  }
}

TEST_CASE("the report states the tolerance only where it chose dt, and the steps per contact dt gives", "[bench]") {
  BenchSpec spec;
  spec.scene.balls = 100;
  spec.steps = 4;
  spec.windows = 1;
  const auto report = [&](PhysicsParams params) {
    World world(params, kScalarKernels, 1, spec.scene.seed);
    REQUIRE(populate(world, spec.scene).empty());
    TunedStepper stepper(world, false);
    return time_steps(stepper, spec, SettleReport{});
  };
  const nlohmann::json chosen = report(PhysicsParams{});
  CHECK(chosen["tolerance"].dump() == "0.005");  // as given, not the float widened to 0.004999999888...
  CHECK(chosen["restitution"].dump() == "0.6");
  CHECK(chosen["steps_per_contact"] == 13);
  CHECK(chosen["dt_from_tolerance"] == true);

  PhysicsParams given_n;
  given_n.steps_per_contact = 20;
  const nlohmann::json by_n = report(given_n);
  CHECK(by_n["tolerance"].is_null());
  CHECK(by_n["steps_per_contact"] == 20);
  CHECK(by_n["dt_from_tolerance"] == false);

  PhysicsParams given_dt;
  given_dt.dt = 5e-4f;
  const nlohmann::json by_dt = report(given_dt);
  CHECK(by_dt["tolerance"].is_null());
  CHECK(by_dt["steps_per_contact"].get<double>() == Approx(contact_duration(given_dt.stiffness) / 5e-4));
  CHECK(by_dt["dt"].get<double>() == Approx(5e-4));
}
