#include "server/options.h"

#include <algorithm>
#include <boost/asio/ip/address.hpp>
#include <boost/program_options.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>
#include <vector>

#include "common/flag_values.h"
#include "common/number_text.h"
#include "common/scene_names.h"
#include "server/physics/worker_pool.h"
#include "server/scenes/scene_presets.h"

#ifndef FISHTANK_DEFAULT_WEB_ROOT
#error "FISHTANK_DEFAULT_WEB_ROOT must name the folder the build puts the browser viewer's page in"
#endif

namespace fishtank {

namespace po = boost::program_options;

namespace {
std::string scene_help() {
  return "scene to start with, which clients may switch live (also --bench's): " + scene_names_text();
}
}  // namespace

ParseResult parse_server_options(int argc, const char* const argv[], const char* variant, bool threaded) {
  ServerOptions o;
  PhysicsParams defaults;
  std::int64_t balls = 0, steps = static_cast<std::int64_t>(o.bench_spec.steps);
  std::int64_t threads = threaded ? WorkerPool::hardware_threads() : 1, max_balls = 0, seed = 1;
  std::int64_t steps_per_contact = defaults.steps_per_contact, prefetch_from = defaults.prefetch_from;
  double dt = defaults.dt;  // read wide: a float would take 1e-46 as 0 (automatic) without a word
  double settle_time = 0.0;
  std::int64_t windows = o.bench_spec.windows;

  // The default names what it follows, not this machine's count, so the flag tables can state it.
  const std::string threads_help = threaded ? "worker threads at most, 1 to 1024 (" + std::to_string(threads) +
                                                  " here); the server steps on one instead while that measures "
                                                  "faster (a busy machine) or for under 2048 balls"
                                            : "worker threads (the scalar build uses 1)";
  po::options_description general("General");
  general.add_options()("help,h", "print this help and exit")(
      "threads", po::value(&threads)->default_value(threads, threaded ? "cores available" : "1"), threads_help.c_str())(
      "fixed-threads", po::bool_switch(&o.fixed_threads),
      "always step on every --threads thread, never on one instead: to time the pool itself")(
      "prefetch-from", po::value(&prefetch_from)->default_value(prefetch_from),
      "balls from which the SIMD step asks memory for rows ahead, 0 to 1e9 (0: always); results do not change, "
      "speed does (scripts/figures-prefetch)")("seed", po::value(&seed)->default_value(seed),
                                               "random seed for spawning, >= 0")(
      "scene", po::value(&o.bench_spec.scene.name)->default_value("tank"), scene_help().c_str())(
      "balls", po::value(&balls),
      "balls of every scene (default: the scene's, 1000 for tank; with --bench, 6000, or as many as the "
      "scene holds where that is fewer)")("max-balls", po::value(&max_balls)->default_value(0),
                                          "most balls the tank may hold (0: its capacity, ~6100; more is refused)")(
      "duration", po::value(&o.duration)->default_value(0.0), "stop after this many seconds (0: run until Ctrl-C)")(
      "status-interval", po::value(&o.status_interval)->default_value(1.0),
      "seconds between status lines, 0.05 to 3600");

  std::int64_t lammps_steps = static_cast<std::int64_t>(o.lammps_steps), record_every = o.record.every;
  po::options_description output("Output (written when the server stops, or after --bench)");
  output.add_options()("dump", po::value(&o.dump_path), "final state as CSV (x,y,z,vx,vy,vz,diameter,mass)")(
      "export-lammps", po::value(&o.lammps_dir),
      "write DIR/data.fishtank and DIR/in.fishtank: the final state and contact model for LAMMPS")(
      "lammps-steps", po::value(&lammps_steps)->default_value(lammps_steps), "steps the exported LAMMPS script runs")(
      "record", po::value(&o.record.path),
      "trajectory in LAMMPS dump format (ASE, MDAnalysis) while the server runs, ending with the final state; "
      "with --bench, the final state")("record-every", po::value(&record_every)->default_value(record_every),
                                       "steps between recorded frames")(
      "record-from", po::value(&o.record.from)->default_value(0.0),
      "simulated seconds before the first recorded frame")(
      "record-constant-count", po::bool_switch(&o.record.constant_count),
      "every frame holds the same balls (for MDAnalysis): start once none are queued, end at the first change of "
      "the count");

  std::int64_t port = o.port, web_port = o.web_port, max_players = o.max_players;
  bool no_web = false;
  o.web_root = FISHTANK_DEFAULT_WEB_ROOT;
  std::string control = "players";
  po::options_description network("Network");
  network.add_options()("bind", po::value(&o.bind)->default_value(o.bind),
                        "address to listen on (127.0.0.1: this machine only; 0.0.0.0: every interface)")(
      "port", po::value(&port)->default_value(port), "TCP port (0: pick a free one and print it)")(
      "web-port", po::value(&web_port)->default_value(web_port),
      "port of the browser viewer: the page over HTTP and WebSocket at /ws, on the --bind address (0: pick a free "
      "one and print it)")("no-web", po::bool_switch(&no_web), "serve no browser viewer (no HTTP/WebSocket port)")(
      "web-root", po::value(&o.web_root)->default_value(o.web_root, "the build's web/dist"),
      "folder of the browser viewer's page, served read-only")(
      "snapshot-rate", po::value(&o.snapshot_rate)->default_value(o.snapshot_rate),
      "snapshots per second sent to clients")("max-players", po::value(&max_players)->default_value(max_players),
                                              "player spheres at most; later clients observe")(
      "control", po::value(&control)->default_value(control),
      "who may pause, step, reset, switch scene and set the time scale: players (clients with a player sphere), "
      "everyone or nobody");

  net::ClientLimits& limits = o.limits;
  std::int64_t max_connections = limits.max_connections, max_pending = limits.max_pending_per_address;
  std::string add_rights = "players";
  po::options_description guard(
      "Limits per client (a peer past one gets an Error saying which; a connection costs the server at most "
      "about 1.1 MiB of memory, so 64 about 72 MiB)");
  guard.add_options()(
      "max-connections", po::value(&max_connections)->default_value(max_connections),
      "clients at most; a newcomer evicts the oldest connection that has not said Hello, or gets server_full "
      "when every client has")(
      "max-pending-per-address", po::value(&max_pending)->default_value(max_pending),
      "connections from one address that have not said Hello; a newcomer beyond it evicts the oldest of them")(
      "hello-timeout", po::value(&limits.hello_timeout_s)->default_value(limits.hello_timeout_s),
      "seconds a new connection has to send its Hello (hello_timeout)")(
      "idle-timeout", po::value(&limits.idle_timeout_s)->default_value(limits.idle_timeout_s),
      "seconds a client may go without reading what it is sent: idle_timeout if it sent nothing either, "
      "too_slow if it did")("player-idle", po::value(&limits.player_idle_s)->default_value(limits.player_idle_s),
                            "seconds a player sphere may stand unmoved, its client sending no control or "
                            "AddBalls, before it is freed and its client observes (player_idle); 0: never")(
      "max-commands", po::value(&limits.max_commands_per_s)->default_value(limits.max_commands_per_s),
      "messages a second per client, as many in a burst; more: command_flood and a disconnect")(
      "add-rights", po::value(&add_rights)->default_value(add_rights),
      "who may add balls: players (clients with a sphere), everyone or nobody; others get not_permitted")(
      "add-rate", po::value(&limits.add_balls_per_minute)->default_value(limits.add_balls_per_minute),
      "balls a minute each client may add, as many at once; beyond it rate_limited");

  po::options_description physics("Physics");
  char stiffness_help[96];
  std::snprintf(stiffness_help, sizeof stiffness_help,
                "contact spring constant k, N/m, %.1f to 1e9 (softer piles sink through the floor)",
                double(softest_stiffness(defaults)));
  physics.add_options()("stiffness", po::value(&o.physics.stiffness)->default_value(defaults.stiffness, "25000"),
                        stiffness_help)("restitution",
                                        po::value(&o.physics.restitution)->default_value(defaults.restitution, "0.6"),
                                        "coefficient of restitution e, (0, 1]")(
      "tolerance", po::value(&o.physics.tolerance)->default_value(defaults.tolerance, "0.005"),
      "largest per-collision restitution error allowed, [0.002, 0.0075]: sets the steps per contact")(
      "steps-per-contact", po::value(&steps_per_contact)->default_value(steps_per_contact),
      "automatic dt = contact duration / this (>= 10; 0: from --tolerance)")(
      "dt", po::value(&dt)->default_value(0.0), "fixed time step in seconds, t_c / 100000 to t_c / 10 (0: automatic)")(
      "skin", po::value(&o.physics.skin)->default_value(defaults.skin, "0"),
      "neighbour-list skin, units, up to 10 (0: follows the motion, 0.1-1)");

  po::options_description bench("Benchmark");
  bench.add_options()("bench", po::bool_switch(&o.bench), "run unpaced without network and print one JSON object")(
      "steps", po::value(&steps)->default_value(steps), "timed steps after settling")(
      "windows", po::value(&windows)->default_value(windows),
      "the timed steps are split into this many windows; rates are their median")(
      "settle-time", po::value(&settle_time)->default_value(0.0),
      "most simulated seconds to wait for rest, 1e-6 J per ball (0: 4 for wide, 300 for the other scenes)");

  po::options_description all;
  all.add(general).add(network).add(guard).add(physics).add(bench).add(output);

  ParseResult result;
  std::ostringstream help;
  help << "fishtank-server (" << variant << " variant): granular physics of balls in a fish tank.\n\n"
       << "Usage: fishtank-server [options]\n"
       << "       fishtank-server --bench [--scene NAME] [--balls N] [--steps S] [--threads T]\n"
       << all;
  po::variables_map vm;
  try {
    po::store(parse_flags(argc, argv, all), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    result.exit_code = 2;
    result.message = "fishtank-server: " + flag_error_text(e, all) + "\nTry --help for the list of options.";
    return result;
  }
  if (vm.count("help")) {
    result.message = help.str();
    return result;
  }

  auto fail = [&result](const std::string& why) {
    result.exit_code = 2;
    result.message = "fishtank-server: " + why;
    return result;
  };
  if (!is_scene_name(o.bench_spec.scene.name))
    return fail("unknown scene '" + o.bench_spec.scene.name + "'; the scenes are " + scene_names_text());
  o.balls_given = vm.count("balls") > 0;
  if (!o.balls_given) balls = o.bench ? 6000 : default_balls(o.bench_spec.scene.name);
  if (balls < 0 || balls > 10'000'000)
    return fail("--balls must be between 0 and 10000000, got " + std::to_string(balls));
  // A rate and a capacity measured on no balls would read as "this build holds none".
  if (o.bench && balls == 0) return fail("--bench times balls: give --balls 1 or more (or leave it out: 6000)");
  if (threads < 1 || threads > 1024)
    return fail("--threads must be between 1 and 1024, got " + std::to_string(threads));
  if (!threaded && threads != 1)
    return fail("the scalar build runs on one thread; drop --threads or use fishtank-server");
  if (seed < 0) return fail("--seed must be >= 0, got " + std::to_string(seed));
  if (steps < 1 || steps > 1'000'000'000)
    return fail("--steps must be between 1 and 1e9, got " + std::to_string(steps));
  if (vm["windows"].defaulted()) windows = std::min<std::int64_t>(windows, steps);  // --steps 3: three windows
  if (windows < 1 || windows > 1000 || windows > steps)
    return fail("--windows must be between 1 and 1000 and at most --steps, got " + std::to_string(windows));
  if (lammps_steps < 0 || lammps_steps > 1'000'000'000'000)
    return fail("--lammps-steps must be between 0 and 1e12, got " + std::to_string(lammps_steps));
  if (record_every < 1 || record_every > 1'000'000'000)
    return fail("--record-every must be between 1 and 1e9 steps, got " + std::to_string(record_every));
  o.lammps_steps = static_cast<std::uint64_t>(lammps_steps);
  o.record.every = static_cast<std::uint32_t>(record_every);
  if (!std::isfinite(o.record.from) || o.record.from < 0.0 || o.record.from > 1e9)
    return fail("--record-from must be between 0 and 1e9 simulated seconds, got " + number_text(o.record.from));
  // An empty name would write nothing without a word.
  for (const char* flag : {"dump", "record", "export-lammps"})
    if (vm.count(flag) && vm[flag].as<std::string>().empty())
      return fail(std::string("--") + flag + " needs a name, got an empty one");
  if (o.record.path.empty())
    for (const char* flag : {"record-every", "record-from", "record-constant-count"})
      if (!vm[flag].defaulted())
        return fail(std::string("--") + flag + " shapes a recording: give --record FILE too, or drop it");
  // A flag of the other mode would go unused without a word.
  const auto given = [&vm](const po::options_description& group, const char* except) -> std::string {
    for (const auto& option : group.options())
      if (option->long_name() != except && vm.count(option->long_name()) && !vm[option->long_name()].defaulted())
        return "--" + option->long_name();
    return "";
  };
  if (const std::string flag = given(bench, "bench"); !o.bench && !flag.empty())
    return fail(flag + " shapes a benchmark: give --bench too, or drop it");
  if (o.bench)
    for (const po::options_description* group : {&network, &guard})
      if (const std::string flag = given(*group, ""); !flag.empty())
        return fail(flag + " is for clients, and --bench runs without a network: drop it");
  if (o.bench)
    for (const char* flag : {"duration", "status-interval"})
      if (!vm[flag].defaulted())
        return fail(std::string("--") + flag + " paces the server, and --bench runs unpaced for --steps: drop it");
  if (prefetch_from < 0 || prefetch_from > 1'000'000'000)
    return fail("--prefetch-from must be between 0 and 1000000000 balls, got " + std::to_string(prefetch_from));
  if (max_balls < 0 || max_balls > 10'000'000)
    return fail("--max-balls must be between 0 and 10000000, got " + std::to_string(max_balls));
  if (!std::isfinite(o.duration) || o.duration < 0.0)
    return fail("--duration must be a number of seconds >= 0, got " + number_text(o.duration));
  if (!std::isfinite(o.status_interval) || o.status_interval < 0.05 || o.status_interval > 3600.0)
    return fail("--status-interval must be between 0.05 and 3600 seconds, got " + number_text(o.status_interval));
  if (!std::isfinite(settle_time) || settle_time < 0.0 || settle_time > 1e6)
    return fail("--settle-time must be between 0 and 1e6 simulated seconds, got " + number_text(settle_time));
  if (steps_per_contact != 0 && (steps_per_contact < PhysicsParams::kMinStepsPerContact ||
                                 steps_per_contact > PhysicsParams::kMaxStepsPerContact))
    return fail("--steps-per-contact must be 0 (from --tolerance) or between " +
                std::to_string(PhysicsParams::kMinStepsPerContact) + " and " +
                std::to_string(PhysicsParams::kMaxStepsPerContact) + ", got " + std::to_string(steps_per_contact));
  o.physics.dt = static_cast<float>(dt);

  // Each sets the time step: of two, one would go unused without a word.
  std::vector<std::string> step_flags;
  if (!vm["tolerance"].defaulted()) step_flags.push_back("--tolerance " + number_text(o.physics.tolerance));
  if (steps_per_contact != 0) step_flags.push_back("--steps-per-contact " + std::to_string(steps_per_contact));
  if (o.physics.dt != 0.0f) step_flags.push_back("--dt " + number_text(o.physics.dt));
  if (step_flags.size() > 1)
    return fail("--tolerance, --steps-per-contact and --dt each set the time step; give one of them, got " +
                step_flags[0] + " and " + step_flags[1]);

  if (boost::system::error_code ec; boost::asio::ip::make_address(o.bind, ec), ec)
    return fail("--bind takes an IP address, such as 127.0.0.1, 0.0.0.0, ::1 or ::, got '" + o.bind + "'");
  if (port < 0 || port > 65535) return fail("--port must be between 0 and 65535, got " + std::to_string(port));
  if (web_port < 0 || web_port > 65535)
    return fail("--web-port must be between 0 and 65535, got " + std::to_string(web_port));
  if (no_web && (!vm["web-port"].defaulted() || !vm["web-root"].defaulted()))
    return fail("--no-web turns the web viewer off: drop --web-port and --web-root, or --no-web");
  // The build's own folder may be unbuilt (the server then says how to build it); a folder given must exist.
  if (std::error_code ec; !vm["web-root"].defaulted() && !std::filesystem::is_directory(o.web_root, ec))
    return fail("--web-root " + o.web_root +
                (std::filesystem::exists(o.web_root, ec) ? " is not a folder" : " does not exist") +
                ": give the folder that holds the page's index.html");
  if (!no_web && port != 0 && port == web_port)
    return fail("--port and --web-port are both " + std::to_string(port) + "; give them different ports");
  if (!std::isfinite(o.snapshot_rate) || o.snapshot_rate < 1.0 || o.snapshot_rate > 1000.0)
    return fail("--snapshot-rate must be between 1 and 1000 per second, got " + number_text(o.snapshot_rate));
  if (max_players < 0 || max_players > 1000)
    return fail("--max-players must be between 0 and 1000, got " + std::to_string(max_players));

  const std::optional<ControlPolicy> policy = parse_control_policy(control);
  if (!policy) return fail("--control must be players, everyone or nobody, got '" + control + "'");
  o.control = *policy;
  if (max_connections < 1 || max_connections > 100000)
    return fail("--max-connections must be between 1 and 100000, got " + std::to_string(max_connections));
  const auto within = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  if (!within(limits.hello_timeout_s, 0.1, 3600.0))
    return fail("--hello-timeout must be between 0.1 and 3600 seconds, got " + number_text(limits.hello_timeout_s));
  if (!within(limits.idle_timeout_s, 0.1, 86400.0))
    return fail("--idle-timeout must be between 0.1 and 86400 seconds, got " + number_text(limits.idle_timeout_s));
  if (!within(limits.player_idle_s, 0.0, 86400.0))
    return fail("--player-idle must be between 0 and 86400 seconds, got " + number_text(limits.player_idle_s));
  if (!within(limits.max_commands_per_s, 1.0, 1e6))
    return fail("--max-commands must be between 1 and 1000000, got " + number_text(limits.max_commands_per_s));
  if (!within(limits.add_balls_per_minute, 0.0, 1e7))
    return fail("--add-rate must be between 0 and 10000000, got " + number_text(limits.add_balls_per_minute));
  const std::optional<ControlPolicy> rights = parse_control_policy(add_rights);
  if (!rights) return fail("--add-rights must be players, everyone or nobody, got '" + add_rights + "'");
  limits.add_rights = *rights;
  if (max_pending < 1 || max_pending > 100000)
    return fail("--max-pending-per-address must be between 1 and 100000, got " + std::to_string(max_pending));
  limits.max_connections = static_cast<std::uint32_t>(max_connections);
  limits.max_pending_per_address = static_cast<std::uint32_t>(max_pending);

  o.port = static_cast<std::uint16_t>(port);
  o.web = !no_web;
  o.web_port = static_cast<std::uint16_t>(web_port);
  o.max_players = static_cast<std::uint32_t>(max_players);
  o.physics.steps_per_contact = static_cast<int>(steps_per_contact);
  o.threads = static_cast<int>(threads);
  o.start_balls = static_cast<std::uint32_t>(balls);
  o.max_balls = static_cast<std::uint32_t>(max_balls);
  o.physics.prefetch_from = static_cast<std::uint32_t>(prefetch_from);
  o.bench_spec.scene.balls = o.start_balls;
  o.bench_spec.scene.seed = static_cast<std::uint64_t>(seed);
  o.bench_spec.scene.max_settle_seconds = settle_time;
  o.bench_spec.steps = static_cast<std::uint64_t>(steps);
  o.bench_spec.windows = static_cast<std::uint32_t>(windows);
  if (o.bench) o.physics.tank = scene_tank(o.bench_spec.scene);
  if (std::string why = validate(o.physics); !why.empty()) return fail(why);
  // What validate cannot see: a dt that a float holds as a denormal or 0 (automatic), far below the floor.
  if (dt > 0.0 && !(o.physics.dt >= std::numeric_limits<float>::min()))
    return fail("--dt " + number_text(dt) + " s " + dt_too_short_text(o.physics.stiffness));
  result.options = o;
  return result;
}

}  // namespace fishtank
