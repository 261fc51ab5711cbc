#pragma once
// Command-line flags of fishtank-server: parsing, defaults and validation.

#include <cstdint>
#include <optional>
#include <string>

#include "server/bench/benchmark.h"
#include "server/control_policy.h"
#include "server/net/client_limits.h"
#include "server/physics/params.h"

namespace fishtank {

struct ServerOptions {
  bool bench = false;
  BenchSpec bench_spec;
  // Steps choose between every thread and one by measurement unless fixed.
  bool fixed_threads = false;
  int threads = 1;
  std::uint32_t start_balls = 1000;  // the scene's default unless --balls was given
  bool balls_given = false;          // --balls applies to every scene a client switches to
  std::uint32_t max_balls = 0;       // 0: the tank's capacity
  double duration = 0.0;             // seconds of real time; 0: until interrupted
  double status_interval = 1.0;
  std::string dump_path;
  std::string lammps_dir;              // --export-lammps
  std::uint64_t lammps_steps = 10000;  // steps the exported script runs
  std::string record_path;             // LAMMPS dump trajectory
  std::uint32_t record_every = 100;    // steps between frames
  PhysicsParams physics;
  // Network (not used by --bench, which never opens a socket).
  std::string bind = "127.0.0.1";
  std::uint16_t port = 7878;  // 0: an ephemeral port, printed at start
  bool web = true;            // --no-web turns the browser viewer's HTTP/WebSocket port off
  std::uint16_t web_port = 8080;
  std::string web_root;  // default: the page as this build tree builds it
  double snapshot_rate = 60.0;
  std::uint32_t max_players = 8;
  ControlPolicy control = ControlPolicy::players;  // who may pause, step, reset, switch scene, set the time scale
  net::ClientLimits limits;
};

struct ParseResult {
  std::optional<ServerOptions> options;  // empty: exit with exit_code after printing message
  int exit_code = 0;
  std::string message;
};

// variant and threaded describe the build, for --help and the threads default.
ParseResult parse_server_options(int argc, const char* const argv[], const char* variant, bool threaded);

}  // namespace fishtank
