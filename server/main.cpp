// fishtank-server: flags and wiring only. The kernel set (scalar, SSE or AVX2)
// is fixed at compile time by FISHTANK_SIMD; all three executables come from this file.

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <iostream>
#include <string>

#include "common/fp_env.h"
#include "common/output_paths.h"
#include "common/time_scale.h"
#include "server/bench/benchmark.h"
#include "server/bench/scenes.h"
#include "server/export/csv_dump.h"
#include "server/export/lammps_export.h"
#include "server/export/trajectory_recorder.h"
#include "server/net/network_service.h"
#include "server/options.h"
#include "server/physics/world_measures.h"
#include "server/realtime_loop.h"
#include "server/scenes/active_scene.h"

#ifndef FISHTANK_SIMD
#error "FISHTANK_SIMD must be defined (0: scalar twin, 1: SSE, 2: AVX2)"
#endif

namespace {

#if FISHTANK_SIMD == 2
const fishtank::Kernels& kKernels = fishtank::kAvx2Kernels;
#elif FISHTANK_SIMD == 1
const fishtank::Kernels& kKernels = fishtank::kSseKernels;
#else
const fishtank::Kernels& kKernels = fishtank::kScalarKernels;
#endif

// Set by SIGINT/SIGTERM (the network service's signal_set) to end the realtime loop.
std::atomic<bool> g_stop{false};

// The final-state files asked for on the command line, and the recording's
// last frame. A benchmark records no frame while it is timed, so its recording
// holds the final state only.
int write_final_state(const fishtank::World& world, const fishtank::ServerOptions& o,
                      fishtank::TrajectoryRecorder& recorder) {
  std::string err;
  if (!o.dump_path.empty()) err = fishtank::write_csv_dump(world, o.dump_path);
  if (err.empty() && !o.lammps_dir.empty()) err = fishtank::export_lammps(world, o.lammps_dir, o.lammps_steps);
  if (const std::string note = recorder.finish(world); !note.empty()) std::cerr << "fishtank-server: " << note << "\n";
  if (!err.empty()) std::cerr << "fishtank-server: " << err << "\n";
  return err.empty() && !recorder.failed() ? 0 : 1;
}

// Whether --dump's and --record's files and --export-lammps's folder can be written (the folder is made); if
// not, why, on stderr: checked before the run, not found when it ends.
bool outputs_writable(const fishtank::ServerOptions& o) {
  std::string error;
  if (!o.dump_path.empty())
    if (const std::string why = fishtank::check_writable_file(o.dump_path); !why.empty())
      error = "--dump " + o.dump_path + ": " + why;
  if (error.empty() && !o.record.path.empty())
    if (const std::string why = fishtank::check_writable_file(o.record.path); !why.empty())
      error = "--record " + o.record.path + ": " + why;
  if (error.empty() && !o.lammps_dir.empty())
    if (const std::string why = fishtank::prepare_writable_folder(o.lammps_dir); !why.empty())
      error = "--export-lammps " + o.lammps_dir + ": " + why;
  if (!error.empty()) std::cerr << "fishtank-server: " << error << "\n";
  return error.empty();
}

// Opens --record's file, if asked for; false (and why, on stderr) if it cannot be written.
bool open_recording(fishtank::TrajectoryRecorder& recorder) {
  const std::string error = recorder.open();
  if (!error.empty()) std::cerr << "fishtank-server: " << error << "\n";
  return error.empty();
}

// --max-balls, refused when the tank cannot hold that many.
bool apply_max_balls(fishtank::World& world, const fishtank::ServerOptions& o) {
  if (o.max_balls == 0) return true;
  const std::string refusal = world.set_max_balls(o.max_balls);
  if (!refusal.empty()) std::cerr << "fishtank-server: --max-balls: " << refusal << "\n";
  return refusal.empty();
}

int run_bench(const fishtank::ServerOptions& o) {
  if (!outputs_writable(o)) return 2;
  fishtank::World world(o.physics, kKernels, o.threads, o.bench_spec.scene.seed);
  fishtank::TunedStepper stepper(world, !o.fixed_threads);
  if (!apply_max_balls(world, o)) return 2;
  // A benchmark times the count asked for or nothing: refused before any is poured. The default count, 6000,
  // becomes what the scene holds where that is fewer.
  fishtank::BenchSpec bench = o.bench_spec;
  const std::string& scene = bench.scene.name;
  const std::uint32_t capacity = fishtank::scene_capacity(world, scene);
  const bool capped = o.max_balls > 0 && o.max_balls <= capacity;  // --max-balls bounds every scene
  if (const std::uint32_t holds = capped ? o.max_balls : capacity; bench.scene.balls > holds) {
    if (o.balls_given) {
      std::cerr << "fishtank-server: --bench refuses --balls " << bench.scene.balls << ": "
                << (capped ? "--max-balls lets in" : "the " + scene + (scene == "tank" ? "" : " scene") + " holds")
                << " at most " << holds << "; use --balls " << holds << " or fewer"
                << (capped ? "" : ", or --scene wide for more") << "\n";
      return 2;
    }
    bench.scene.balls = holds;
  }
  fishtank::TrajectoryRecorder recorder(o.record);
  if (!open_recording(recorder)) return 1;
  if (std::string refusal = fishtank::populate(world, bench.scene); !refusal.empty()) {
    std::cerr << "fishtank-server: --bench refuses: " << refusal << "\n";
    return 2;
  }
  fishtank::SettleReport settled = fishtank::settle(stepper, bench.scene);
  if (!settled.settled)
    std::cerr << "fishtank-server: warning: not at rest after " << settled.sim_seconds
              << " simulated seconds; timing anyway\n";
  std::cerr << "timing " << bench.steps << " steps of " << world.ball_count() << " balls\n";
  nlohmann::json report = fishtank::time_steps(stepper, bench, settled);
  if (const std::string warning = overlap_warning(world); !warning.empty())
    std::cerr << "fishtank-server: warning: " << warning << "\n";
  std::cout << report.dump(2) << std::endl;
  return write_final_state(world, o, recorder);
}

// "2 threads", or "3 threads on 2 cores: oversubscribed": more threads than
// cores is allowed, but then they take turns and the figures should say so.
// Work in other sessions of half a core or more, which can keep the steps on one thread, is named too.
std::string threads_text(int threads, int cores, double crowding_cores = -1.0) {
  std::string text = std::to_string(threads) + (threads == 1 ? " thread" : " threads");
  if (threads > cores) text += " on " + std::to_string(cores) + (cores == 1 ? " core" : " cores") + ": oversubscribed";
  if (crowding_cores >= 0.5) {
    char others[64];
    std::snprintf(others, sizeof others, " (other sessions keep %.1f cores busy)", crowding_cores);
    text += others;
  }
  return text;
}

// Nothing while simulated time keeps up with the wall clock at the pace asked for.
std::string pace_text(const fishtank::LoopStatus& s, const fishtank::RunControl& control) {
  if (control.paused) return "  paused";
  char text[64] = "";
  if (control.time_scale < 1.0) std::snprintf(text, sizeof text, "  time scale set to x%.2f", control.time_scale);
  std::string pace = text;
  if (fishtank::slow_motion(s.pace_kept)) {
    std::snprintf(text, sizeof text, "  slow motion x%.2f", s.time_scale);
    return pace + text;
  }
  return pace + (s.dropped_steps ? "  (falling behind)" : "");
}

fishtank::net::NetOptions net_options(const fishtank::ServerOptions& o) {
  fishtank::net::NetOptions net;
  net.bind = o.bind;
  net.port = o.port;
  net.web = o.web;
  net.web_port = o.web_port;
  net.web_root = o.web_root;
  net.link.snapshot_rate_hz = o.snapshot_rate;
  net.link.max_players = o.max_players;
  return net;
}

fishtank::net::ServerInfo server_info(const fishtank::World& world, const fishtank::ServerOptions& o) {
  fishtank::net::ServerInfo info;
  info.variant = kKernels.variant;
  info.simd = kKernels.simd;
  info.worker_threads = static_cast<std::uint32_t>(world.threads());
  info.tank = world.params().tank;
  info.dt = world.dt();
  info.steps_per_contact = fishtank::contact_duration(o.physics.stiffness) / world.dt();
  info.tolerance = fishtank::dt_from_tolerance(o.physics) ? o.physics.tolerance : 0.0f;
  info.snapshot_rate_hz = static_cast<float>(o.snapshot_rate);
  info.control = o.control;
  info.limits = o.limits;
  return info;
}

fishtank::SceneChoice scene_choice(const fishtank::ServerOptions& o) {
  fishtank::SceneChoice choice;
  choice.name = o.bench_spec.scene.name;
  choice.seed = o.bench_spec.scene.seed;
  if (o.balls_given) choice.balls = o.start_balls;
  choice.max_balls = o.max_balls;
  return choice;
}

int run_server(const fishtank::ServerOptions& o) {
  if (!outputs_writable(o)) return 2;
  spdlog::set_default_logger(spdlog::stderr_logger_mt("fishtank-server"));
  fishtank::ActiveScene scene(scene_choice(o));
  fishtank::PhysicsParams params = o.physics;
  params.tank = scene.first_tank();
  fishtank::World world(params, kKernels, o.threads, o.bench_spec.scene.seed);
  fishtank::TunedStepper stepper(world, !o.fixed_threads);
  if (!apply_max_balls(world, o)) return 2;
  if (std::string refusal = scene.start(world); !refusal.empty()) std::cerr << "fishtank-server: " << refusal << "\n";
  fishtank::RunControl control;
  fishtank::net::NetworkService network(net_options(o), server_info(world, o), control, scene, g_stop);
  if (std::string error = network.start(); !error.empty()) {
    std::cerr << "fishtank-server: " << error << "\n";
    return 1;
  }
  // Only once it listens: a server that cannot start must not first read as one that runs.
  const int cores = fishtank::WorkerPool::hardware_threads();
  char step_rule[96];
  if (o.physics.dt > 0.0f)
    std::snprintf(step_rule, sizeof step_rule, "given");
  else if (o.physics.steps_per_contact > 0)
    std::snprintf(step_rule, sizeof step_rule, "%d steps per contact, given", o.physics.steps_per_contact);
  else
    std::snprintf(step_rule, sizeof step_rule, "%d steps per contact: each collision's e within %g",
                  steps_per_contact(o.physics), double(o.physics.tolerance));
  std::fprintf(stderr, "fishtank-server (%s, %s, %s): dt = %.3g s (%s), k = %g N/m, e = %g; Ctrl-C stops\n",
               kKernels.variant, kKernels.simd, threads_text(world.threads(), cores).c_str(), world.dt(), step_rule,
               o.physics.stiffness, o.physics.restitution);
  fishtank::TrajectoryRecorder recorder(o.record);
  if (!open_recording(recorder)) return 1;
  fishtank::LoopOptions loop;
  loop.duration = o.duration;
  loop.status_interval = o.status_interval;
  loop.batch_seconds = std::min(0.004, 1.0 / o.snapshot_rate);  // 4 ms, or one snapshot interval if shorter
  loop.control = &control;
  if (!o.record.path.empty()) loop.boundary_every = o.record.every;
  loop.at_step_boundary = [&](fishtank::World& w, const fishtank::LoopStatus& s) {
    network.at_step_boundary(w, s);
    if (const std::string note = recorder.at_step_boundary(w); !note.empty()) spdlog::warn("{}", note);
  };
  loop.on_status = [&network, &control, &scene, cores](const fishtank::World& w, const fishtank::LoopStatus& s) {
    const std::string warning = overlap_warning(w);
    std::fprintf(
        stderr, "t = %7.1f s  balls %5u (+%u queued)  %6.0f steps/s  load %5.1f %% on %s  %s  scene %s%s%s%s\n",
        w.time(), w.ball_count(), w.pending(), s.steps_per_s, 100.0 * s.load,
        threads_text(s.threads, cores, s.crowding_cores).c_str(), network.status().c_str(), scene.name().c_str(),
        pace_text(s, control).c_str(), warning.empty() ? "" : "  WARNING: ", warning.c_str());
  };
  fishtank::run_realtime(stepper, loop, g_stop);
  network.stop(g_stop ? "it was stopped (Ctrl-C or SIGTERM)" : "its --duration ended");
  std::cerr << "fishtank-server: stopped after " << world.steps() << " steps, " << world.ball_count() << " balls\n";
  return write_final_state(world, o, recorder);
}

}  // namespace

int main(int argc, char** argv) {
  if (FISHTANK_SIMD == 2 && !fishtank::cpu_has_avx2()) {
    std::cerr << "fishtank-server-avx2: this processor has no AVX2; use fishtank-server (SSE4.1) instead\n";
    return 1;
  }
  fishtank::ParseResult parsed = fishtank::parse_server_options(argc, argv, kKernels.variant, kKernels.threaded);
  if (!parsed.options) {
    (parsed.exit_code == 0 ? std::cout : std::cerr) << parsed.message << "\n";
    return parsed.exit_code;
  }
  fishtank::enable_flush_denormals_to_zero();
  const fishtank::ServerOptions& o = *parsed.options;
  return o.bench ? run_bench(o) : run_server(o);
}
