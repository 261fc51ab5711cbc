// fishtank-server: flags and wiring only. The variant (scalar or SSE) is fixed
// at compile time by FISHTANK_SIMD; both executables come from this file.

#include <csignal>
#include <cstdio>
#include <iostream>

#include "common/fp_env.h"
#include "server/bench/benchmark.h"
#include "server/bench/scenes.h"
#include "server/export/csv_dump.h"
#include "server/options.h"
#include "server/realtime_loop.h"

#ifndef FISHTANK_SIMD
#error "FISHTANK_SIMD must be defined (0: scalar twin, 1: SSE)"
#endif

namespace {

#if FISHTANK_SIMD
const fishtank::Kernels& kKernels = fishtank::kSseKernels;
#else
const fishtank::Kernels& kKernels = fishtank::kScalarKernels;
#endif

std::atomic<bool> g_stop{false};

void request_stop(int) { g_stop = true; }

int write_dump_if_asked(const fishtank::World& world, const fishtank::ServerOptions& o) {
  if (o.dump_path.empty()) return 0;
  if (std::string err = fishtank::write_csv_dump(world, o.dump_path); !err.empty()) {
    std::cerr << "fishtank-server: " << err << "\n";
    return 1;
  }
  return 0;
}

int run_bench(const fishtank::ServerOptions& o) {
  fishtank::World world(o.physics, kKernels, o.threads, o.bench_spec.scene.seed);
  if (std::string refusal = fishtank::populate(world, o.bench_spec.scene); !refusal.empty()) {
    std::cerr << "fishtank-server: " << refusal << "\n";
    return 2;
  }
  fishtank::SettleReport settled = fishtank::settle(world, o.bench_spec.scene);
  if (!settled.settled)
    std::cerr << "fishtank-server: warning: not at rest after " << settled.sim_seconds
              << " simulated seconds; timing anyway\n";
  std::cerr << "timing " << o.bench_spec.steps << " steps of " << world.ball_count() << " balls\n";
  nlohmann::json report = fishtank::time_steps(world, o.bench_spec, settled);
  std::cout << report.dump(2) << std::endl;
  return write_dump_if_asked(world, o);
}

int run_server(const fishtank::ServerOptions& o) {
  fishtank::World world(o.physics, kKernels, o.threads, o.bench_spec.scene.seed);
  if (o.max_balls > 0) world.set_max_balls(o.max_balls);
  if (o.start_balls > 0) {
    fishtank::AddResult added = world.add_balls(o.start_balls);
    if (!added.refusal.empty()) std::cerr << "fishtank-server: " << added.refusal << "\n";
  }
  std::fprintf(stderr, "fishtank-server (%s, %s, %d threads): dt = %.3g s, k = %g N/m, e = %g; Ctrl-C stops\n",
               kKernels.variant, kKernels.simd, world.threads(), world.dt(), o.physics.stiffness,
               o.physics.restitution);
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
  fishtank::LoopOptions loop;
  loop.duration = o.duration;
  loop.status_interval = o.status_interval;
  loop.on_status = [](const fishtank::World& w, const fishtank::LoopStatus& s) {
    std::fprintf(stderr, "t = %7.1f s  balls %5u (+%u queued)  %6.0f steps/s  load %5.1f %%%s\n", w.time(),
                 w.ball_count(), w.pending(), s.steps_per_s, 100.0 * s.load,
                 s.dropped_steps ? "  (falling behind real time)" : "");
  };
  fishtank::run_realtime(world, loop, g_stop);
  std::cerr << "fishtank-server: stopped after " << world.steps() << " steps, " << world.ball_count() << " balls\n";
  return write_dump_if_asked(world, o);
}

}  // namespace

int main(int argc, char** argv) {
  fishtank::ParseResult parsed =
      fishtank::parse_server_options(argc, argv, kKernels.variant, kKernels.threaded);
  if (!parsed.options) {
    (parsed.exit_code == 0 ? std::cout : std::cerr) << parsed.message << "\n";
    return parsed.exit_code;
  }
  fishtank::enable_flush_denormals_to_zero();
  const fishtank::ServerOptions& o = *parsed.options;
  return o.bench ? run_bench(o) : run_server(o);
}
