// The paced loop keeps calling back between batches at the snapshot rate
// whatever a step costs: a world far over its real-time budget runs in slow
// motion and says so, and one within it keeps real time. People's controls:
// a paused loop steps only what is asked and keeps calling back, and a time
// scale set below 1 slows simulated time by that much, without reading as
// an overload. However far apart steps come (soft contacts, a slow clock)
// they come, and the loop still calls back at its rate; the rates it passes
// between batches cover the last second, whatever the status interval.

#include "server/realtime_loop.h"

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <vector>

#include "common/time_scale.h"

using namespace fishtank;

namespace {

struct Observed {
  double boundaries_per_s = 0.0;  // at_step_boundary calls, where snapshots go out
  LoopStatus last_boundary;       // what the last of them saw
  std::vector<double> time_scales;
  std::vector<double> loads;  // the status lines' and the batches' alike
  double sim_seconds = 0.0;
  double wall_seconds = 0.0;
};

Observed run_paced(World& world, double seconds, RunControl* control = nullptr, double status_interval = 0.25) {
  LoopOptions options;
  options.control = control;
  options.duration = seconds;
  options.status_interval = status_interval;
  Observed seen;
  int boundaries = 0;
  options.at_step_boundary = [&](World&, const LoopStatus& s) {
    ++boundaries;
    seen.last_boundary = s;
    seen.loads.push_back(s.load);
  };
  options.on_status = [&](const World&, const LoopStatus& s) {
    seen.time_scales.push_back(s.time_scale);
    seen.loads.push_back(s.load);
  };
  const double sim_before = world.time();
  const auto start = std::chrono::steady_clock::now();
  const std::atomic<bool> stop{false};
  TunedStepper stepper(world, false);
  run_realtime(stepper, options, stop);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  seen.boundaries_per_s = boundaries / wall;
  seen.wall_seconds = wall;
  seen.sim_seconds = world.time() - sim_before;
  return seen;
}

PhysicsParams with_stiffness(float stiffness) {
  PhysicsParams params;
  params.stiffness = stiffness;
  return params;
}

// run_paced with the clock set to `scale` of real time, as a viewer's [ and ] keys set it.
Observed run_slowed(World& world, double seconds, double scale) {
  RunControl control;
  control.time_scale = scale;
  return run_paced(world, seconds, &control);
}

// `balls` in a lattice, at rest.
void place_lattice(World& world, int balls) {
  for (int b = 0; b < balls; ++b)
    world.place_ball(b % kKindCount,
                     {-18.5f + 3.1f * (b % 12), 1.6f + 3.1f * (b / 144), -18.5f + 3.1f * ((b / 12) % 12)},
                     {0.0f, 0.0f, 0.0f});
}

// A lattice of 100 balls in a loop that people control (control), run for `seconds`, set up in options.
struct ControlledLoop {
  World world{with_stiffness(25000.0f), kSseKernels, 1, 5};
  RunControl control;
  LoopOptions options;
  std::chrono::steady_clock::time_point start;

  explicit ControlledLoop(double seconds) {
    place_lattice(world, 100);
    options.control = &control;
    options.duration = seconds;
  }
  double since_start() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
  void run() {
    const std::atomic<bool> stop{false};
    TunedStepper stepper(world, false);
    start = std::chrono::steady_clock::now();
    run_realtime(stepper, options, stop);
  }
};

}  // namespace

TEST_CASE("a world far over its real-time budget runs in slow motion, and the loop keeps its rate", "[server][loop]") {
  // Stiff contacts make dt tiny: real time would need far more steps per second than one thread runs.
  World world(with_stiffness(1e9f), kSseKernels, 1, 5);
  place_lattice(world, 1500);
  const Observed seen = run_paced(world, 1.5);
  INFO("dt " << world.dt() << " s, " << seen.boundaries_per_s << " batches/s, simulated " << seen.sim_seconds << " s");
  // Each batch keeps to its budget (4 ms), so the loop comes round at least 30 times a second.
  CHECK(seen.boundaries_per_s >= 30.0);
  REQUIRE(seen.time_scales.size() >= 3);
  const double last = seen.time_scales.back();
  CHECK(last > 0.0);
  CHECK(last < 0.8);
  // The time scale reported is the simulated time the loop advanced.
  CHECK(seen.sim_seconds < 0.9 * 1.5);
  // One thread, busy all the time: a share of the wall clock, not of the time steps fell due (which a
  // loop behind lets slip), so never above 1.
  for (const double load : seen.loads) CHECK(load <= 1.0);
  CHECK(seen.loads.back() > 0.8);
}

TEST_CASE("a world within its budget keeps real time", "[server][loop]") {
  World world(with_stiffness(25000.0f), kSseKernels, 1, 5);
  place_lattice(world, 100);
  const Observed seen = run_paced(world, 1.0);
  REQUIRE(seen.time_scales.size() >= 3);
  CHECK(seen.time_scales.back() == Approx(1.0).margin(0.1));
  CHECK(seen.sim_seconds == Approx(1.0).margin(0.1));
}

TEST_CASE("a paused loop runs exactly the steps asked for and keeps calling back at its rate", "[server][loop]") {
  World world(with_stiffness(25000.0f), kSseKernels, 1, 5);
  place_lattice(world, 100);
  RunControl control;
  control.paused = true;
  control.steps_to_run = 37;
  const Observed seen = run_paced(world, 0.5, &control);
  CHECK(world.steps() == 37);
  CHECK(control.steps_to_run == 0);
  CHECK(seen.boundaries_per_s >= 30.0);  // snapshots and commands go on while paused
}

TEST_CASE("a time scale of one half advances half the simulated time, and is not called slow motion",
          "[server][loop]") {
  World world(with_stiffness(25000.0f), kSseKernels, 1, 5);
  place_lattice(world, 100);
  const double scale = 0.5;
  const Observed seen = run_slowed(world, 1.0, scale);
  CHECK(seen.sim_seconds == Approx(0.5).margin(0.06));
  REQUIRE(seen.time_scales.size() >= 3);
  CHECK(seen.time_scales.back() == Approx(0.5).margin(0.06));
  CHECK_FALSE(slow_motion(seen.time_scales.back(), scale));
  CHECK(slow_motion(seen.time_scales.back()));  // against real time it is slower
}

TEST_CASE("a step due later than the loop lets lag accrue still comes: soft contacts at a tenth of real time",
          "[server][loop]") {
  // k = 1000 N/m: dt = 5.4 ms, 54 ms of wall time a step at x0.1, more than the 50 ms of lag caught up on.
  World world(with_stiffness(1000.0f), kSseKernels, 1, 5);
  place_lattice(world, 100);
  const double scale = 0.1;
  const Observed seen = run_slowed(world, 1.5, scale);
  INFO("dt " << world.dt() << " s, " << world.steps() << " steps");
  CHECK(seen.sim_seconds == Approx(0.15).margin(0.03));
  CHECK(seen.boundaries_per_s >= 30.0);
  // Its windows are timed on when steps fell due: timed on the wall clock, a window ending between
  // two steps or at one woken late would count a step short and read as slow motion.
  REQUIRE(seen.time_scales.size() >= 3);
  for (const double time_scale : seen.time_scales) CHECK_FALSE(slow_motion(time_scale, scale));
}

TEST_CASE("steps seconds apart leave the loop calling back at its rate and stopping on time", "[server][loop]") {
  // k = 1 N/m, the softest accepted without gravity: dt = 0.17 s, 1.7 s of wall time a step at x0.1.
  PhysicsParams params = with_stiffness(1.0f);
  params.gravity = 0.0f;
  REQUIRE(validate(params).empty());
  World world(params, kSseKernels, 1, 5);
  place_lattice(world, 100);
  const Observed seen = run_slowed(world, 0.5, 0.1);
  INFO("dt " << world.dt() << " s");
  CHECK(seen.boundaries_per_s >= 30.0);  // commands, snapshots and stop are not kept waiting for the step
  CHECK(seen.wall_seconds < 1.0);
}

TEST_CASE("the rates seen between batches cover the last second, however far apart the status lines are",
          "[server][loop]") {
  World world(with_stiffness(25000.0f), kSseKernels, 1, 5);
  place_lattice(world, 100);
  const Observed seen = run_paced(world, 2.5, nullptr, /*status_interval=*/60.0);
  CHECK(seen.time_scales.empty());  // no status line yet
  CHECK(seen.last_boundary.steps_per_s == Approx(1.0 / world.dt()).epsilon(0.1));
  CHECK(seen.last_boundary.time_scale == Approx(1.0).margin(0.1));
  CHECK(seen.last_boundary.load > 0.0);
}

TEST_CASE("a batch ends at every multiple of boundary_every, running and paused, so a recording gets each",
          "[server][loop]") {
  ControlledLoop loop(0.8);  // 150 steps due in 0.16 s, then 100 back to back: room for a busy machine
  loop.options.boundary_every = 7;
  std::vector<std::uint64_t> boundaries;  // the step at each at_step_boundary
  loop.options.at_step_boundary = [&](World& w, const LoopStatus&) {
    boundaries.push_back(w.steps());
    if (w.steps() >= 150 && !loop.control.paused) {  // then paused, a run of asked-for steps back to back
      loop.control.paused = true;
      loop.control.steps_to_run = 100;
    }
  };
  loop.run();
  REQUIRE(loop.control.steps_to_run == 0);
  REQUIRE(loop.world.steps() >= 250);
  for (std::uint64_t step = 0; step + 7 <= loop.world.steps(); step += 7) {
    INFO("step " << step);
    CHECK(std::find(boundaries.begin(), boundaries.end(), step) != boundaries.end());
  }
}

TEST_CASE(
    "a window in which people resumed or set another time scale is not read as slow motion, and its time "
    "scale is the simulated seconds per wall second it ran",
    "[server][loop]") {
  ControlledLoop loop(2.6);
  loop.control.paused = true;
  loop.options.status_interval = 0.5;
  constexpr double kResumeAt = 0.2;  // inside the first line's window, which is checked too
  loop.options.at_step_boundary = [&](World&, const LoopStatus&) {
    const double t = loop.since_start();
    loop.control.paused = t < kResumeAt;            // paused, then resumed at half the clock
    loop.control.time_scale = t < 1.3 ? 0.5 : 1.0;  // then back to real time, inside a line's window
  };
  struct Line {
    double at, sim, time_scale, pace_kept;
  };
  std::vector<Line> lines{{0.0, loop.world.time(), 0.0, 0.0}};  // the start, where the first window opens
  loop.options.on_status = [&](const World& world, const LoopStatus& s) {
    lines.push_back({loop.since_start(), world.time(), s.time_scale, s.pace_kept});
  };
  loop.run();
  REQUIRE(lines.size() >= 5);
  int running = 0;
  for (std::size_t k = 1; k < lines.size(); ++k) {
    const Line &from = lines[k - 1], &l = lines[k];
    const double ran = l.at - std::max(from.at, kResumeAt);  // wall seconds not paused
    if (ran < 0.25) continue;
    ++running;
    INFO("line at " << l.at << " s: time scale " << l.time_scale << ", " << (l.sim - from.sim) / ran
                    << " simulated seconds per wall second, pace kept " << l.pace_kept);
    CHECK_FALSE(slow_motion(l.pace_kept));
    CHECK(l.time_scale == Approx((l.sim - from.sim) / ran).margin(0.1));
  }
  CHECK(running >= 4);  // the resume's window among them
}

TEST_CASE("the rates between batches tell a pause or a resume within a fifth of a second, not a second on",
          "[server][loop]") {
  ControlledLoop loop(2.3);
  int paused_checked = 0, running_checked = 0;
  loop.options.at_step_boundary = [&](World& w, const LoopStatus& s) {
    const double t = loop.since_start();
    // Running 0.7 s (the live window closes at 1 s), paused until 1.4 s, then running again.
    loop.control.paused = t >= 0.7 && t < 1.4;
    INFO("t " << t << " s: " << s.steps_per_s << " steps/s, time scale " << s.time_scale);
    if (t > 1.0 && t < 1.4) {  // paused 0.3 s: the steps of the running part are gone
      CHECK(s.steps_per_s == 0.0);
      ++paused_checked;
    }
    if (t > 1.7) {  // running again 0.3 s (half the pace at least: a busy machine may drop steps)
      CHECK(s.steps_per_s > 0.5 / w.dt());
      CHECK(s.time_scale > 0.5);
      ++running_checked;
    }
  };
  loop.run();
  CHECK(paused_checked > 10);
  CHECK(running_checked > 10);
}
