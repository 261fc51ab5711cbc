// fishtank-server's command line: every bad value is refused with a message
// that names the flag and a non-zero exit code, before anything starts;
// --help lists every flag; good values land where the server reads them.

#include "server/options.h"

#include <catch2/catch.hpp>
#include <filesystem>
#include <string>
#include <vector>

#include "server/physics/worker_pool.h"
#include "server/scenes/scene_presets.h"

using namespace fishtank;

namespace {

ParseResult parse(std::vector<std::string> args, const char* variant = "sse", bool threaded = true) {
  args.insert(args.begin(), "fishtank-server");
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  return parse_server_options(static_cast<int>(argv.size()), argv.data(), variant, threaded);
}

}  // namespace

TEST_CASE("no flags: the paced server with 1000 balls on every core and the default physics", "[options]") {
  const ParseResult r = parse({});
  REQUIRE(r.options);
  CHECK(r.exit_code == 0);
  CHECK_FALSE(r.options->bench);
  CHECK(r.options->start_balls == 1000);
  CHECK(r.options->threads == WorkerPool::hardware_threads());
  CHECK(r.options->port == 7878);
  CHECK(r.options->bind == "127.0.0.1");
  CHECK(r.options->web);
  CHECK(r.options->web_port == 8080);
  CHECK(r.options->web_root == FISHTANK_DEFAULT_WEB_ROOT);
  CHECK(r.options->limits.max_pending_per_address == 8);
  CHECK(r.options->physics.stiffness == PhysicsParams{}.stiffness);
}

TEST_CASE("the help text (--help) lists every flag and exits 0 without starting anything", "[options]") {
  const ParseResult r = parse({"--help"});
  CHECK_FALSE(r.options);
  CHECK(r.exit_code == 0);
  for (const char* flag : {"--help",
                           "--threads",
                           "--seed",
                           "--balls",
                           "--max-balls",
                           "--duration",
                           "--status-interval",
                           "--bind",
                           "--port",
                           "--web-port",
                           "--no-web",
                           "--web-root",
                           "--snapshot-rate",
                           "--max-players",
                           "--control",
                           "--max-connections",
                           "--max-pending-per-address",
                           "--hello-timeout",
                           "--idle-timeout",
                           "--player-idle",
                           "--max-commands",
                           "--add-rights",
                           "--add-rate",
                           "--stiffness",
                           "--restitution",
                           "--steps-per-contact",
                           "--dt",
                           "--skin",
                           "--prefetch-from",
                           "--bench",
                           "--scene",
                           "--steps",
                           "--windows",
                           "--settle-time",
                           "--dump",
                           "--export-lammps",
                           "--lammps-steps",
                           "--record",
                           "--record-every",
                           "--record-from",
                           "--record-constant-count"}) {
    INFO(flag);
    CHECK(r.message.find(flag) != std::string::npos);
  }
  // Defaults are shown beside their flags.
  CHECK(r.message.find("--stiffness arg (=25000)") != std::string::npos);
  CHECK(r.message.find("--skin arg (=0)") != std::string::npos);
}

TEST_CASE("the wide benchmark's flags give its spec, and a tank widened for the balls", "[options]") {
  const ParseResult r = parse({"--bench", "--scene", "wide", "--balls", "100000", "--steps", "50", "--seed", "7"});
  REQUIRE(r.options);
  const ServerOptions& o = *r.options;
  CHECK(o.bench);
  CHECK(o.bench_spec.scene.name == "wide");
  CHECK(o.bench_spec.scene.balls == 100000);
  CHECK(o.bench_spec.scene.seed == 7);
  CHECK(o.bench_spec.steps == 50);
  CHECK(o.physics.tank.size().x > 200.0f);  // 40 units would hold ~6000
  CHECK(o.physics.tank.size().y == 40.0f);
  // Without --balls the benchmark fills the product's tank.
  CHECK(parse({"--bench"}).options->start_balls == 6000);
  // Fewer steps than the default windows: one window per step, not a refusal of a flag not given.
  CHECK(parse({"--bench"}).options->bench_spec.windows == 5);
  CHECK(parse({"--bench", "--steps", "3"}).options->bench_spec.windows == 3);
}

TEST_CASE(
    "an interactive scene starts with its own number of balls unless --balls says, and --control sets who may "
    "use the sandbox's controls",
    "[options]") {
  const ParseResult drop = parse({"--scene", "drop"});
  REQUIRE(drop.options);
  CHECK(drop.options->bench_spec.scene.name == "drop");
  CHECK(drop.options->start_balls == default_balls("drop"));
  CHECK_FALSE(drop.options->balls_given);
  CHECK(drop.options->control == ControlPolicy::players);
  const ParseResult given = parse({"--scene", "dam-break", "--balls", "500", "--control", "everyone"});
  REQUIRE(given.options);
  CHECK(given.options->start_balls == 500);
  CHECK(given.options->balls_given);
  CHECK(given.options->control == ControlPolicy::everyone);
  CHECK(parse({"--control", "nobody"}).options->control == ControlPolicy::nobody);
}

TEST_CASE("the recording's flags land in its options, by default every 100 steps from t = 0 and any count",
          "[options]") {
  const ParseResult plain = parse({"--record", "t.dump"});
  REQUIRE(plain.options);
  CHECK(plain.options->record.path == "t.dump");
  CHECK(plain.options->record.every == 100);
  CHECK(plain.options->record.from == 0.0);
  CHECK_FALSE(plain.options->record.constant_count);
  const ParseResult r =
      parse({"--record", "t.dump", "--record-every", "40", "--record-from", "2.5", "--record-constant-count"});
  REQUIRE(r.options);
  CHECK(r.options->record.every == 40);
  CHECK(r.options->record.from == 2.5);
  CHECK(r.options->record.constant_count);
}

TEST_CASE("every bad value is refused with a message naming it and exit code 2", "[options]") {
  struct Bad {
    std::vector<std::string> args;
    std::string says;
  };
  const std::vector<Bad> bad = {
      {{"--balls", "-5"}, "--balls must be between"},
      {{"--balls", "-1"}, "--balls must be between"},  // -1 once meant "not given"
      {{"--balls", "20000000"}, "--balls must be between"},
      {{"--balls", "many"}, "balls"},
      {{"--threads", "0"}, "--threads must be between"},
      {{"--seed", "-1"}, "--seed must be >= 0"},
      {{"--bench", "--steps", "0"}, "--steps must be between"},
      {{"--bench", "--steps", "5", "--windows", "10"}, "--windows must be"},
      {{"--duration", "nan"}, "--duration"},
      {{"--duration", "-1"}, "--duration"},
      {{"--status-interval", "0"}, "--status-interval"},
      {{"--bench", "--settle-time", "inf"}, "--settle-time must be between"},
      {{"--bench", "--scene", "cube"}, "unknown scene 'cube'"},
      {{"--scene", "cube"}, "unknown scene 'cube'; the scenes are tank, wide, dam-break and drop"},
      {{"--control", "observers"}, "--control must be players, everyone or nobody"},
      {{"--port", "70000"}, "--port must be between"},
      {{"--web-port", "-1"}, "--web-port must be between"},
      {{"--port", "9000", "--web-port", "9000"}, "--port and --web-port are both 9000"},
      {{"--no-web", "--web-port", "9000"}, "--no-web turns the web viewer off"},
      {{"--max-pending-per-address", "0"}, "--max-pending-per-address must be between"},
      {{"--snapshot-rate", "0"}, "--snapshot-rate"},
      {{"--max-players", "-1"}, "--max-players"},
      {{"--max-balls", "-3"}, "--max-balls"},
      {{"--record-every", "0"}, "--record-every"},
      {{"--record", "t.dump", "--record-from", "-1"}, "--record-from must be between 0 and 1e9"},
      {{"--record", "t.dump", "--record-from", "nan"}, "--record-from must be between 0 and 1e9"},
      {{"--record-from", "5"}, "--record-from shapes a recording: give --record FILE too"},
      {{"--record-every", "5"}, "--record-every shapes a recording: give --record FILE too"},
      {{"--record-constant-count"}, "--record-constant-count shapes a recording: give --record FILE too"},
      {{"--lammps-steps", "-1"}, "--lammps-steps"},
      {{"--stiffness", "nan"}, "stiffness"},
      {{"--stiffness", "-1"}, "stiffness"},
      {{"--stiffness", "300"}, "too soft for gravity 9.81 m/s^2 in a tank 40 high"},
      {{"--stiffness", "0.5"}, "stiffness k must be in [784.8, 1e9] N/m, got 0.5"},
      {{"--restitution", "0"}, "restitution"},
      {{"--restitution", "1.5"}, "restitution"},
      {{"--steps-per-contact", "5"},
       "--steps-per-contact must be 0 (from --tolerance) or between 10 and 100000, got 5"},
      {{"--tolerance", "0.02"}, "fewer than 10 steps per contact, which is unstable"},
      {{"--tolerance", "0.0001"}, "float32 positions cannot resolve a slow contact"},
      {{"--tolerance", "nan"}, "tolerance must be in [0.002, 0.0075]"},
      {{"--dt", "0.01"}, "unstable for k"},
      // Below t_c / 100000, and where a float would read it as 0 (automatic) or a denormal.
      {{"--dt", "1e-8"},
       "dt = 1e-08 s is too short for k = 25000 N/m: at most 100000 steps per contact, so dt must be"},
      {{"--dt", "1e-40"}, "s is too short for k = 25000 N/m"},
      {{"--dt", "1e-46"}, "--dt 1e-46 s is too short for k = 25000 N/m"},
      {{"--stiffness", "0", "--dt", "0.001"}, "stiffness k must be in"},  // the stiffness first, not a dt floor of inf
      {{"--tolerance", "0.002", "--steps-per-contact", "15"},
       "--tolerance, --steps-per-contact and --dt each set the time step; give one of them, got --tolerance 0.002 "
       "and --steps-per-contact 15"},
      {{"--steps-per-contact", "15", "--dt", "0.001"}, "got --steps-per-contact 15 and --dt 0.001"},
      {{"--bind", "localhost"}, "--bind takes an IP address, such as 127.0.0.1, 0.0.0.0, ::1 or ::, got 'localhost'"},
      {{"--balls", "nan"}, "the argument ('nan') for option '--balls' is invalid: it takes a whole number"},
      {{"--stiffness", "stiff"}, "for option '--stiffness' is invalid: it takes a number"},
      {{"--seed", "99999999999999999999"}, "for option '--seed' is invalid: that number is far too large"},
      {{"--skin", "-0.1"}, "skin"},
      {{"--prefetch-from", "-1"}, "--prefetch-from must be between 0 and 1000000000 balls, got -1"},
      {{"--max-connections", "0"}, "--max-connections must be between"},
      {{"--hello-timeout", "0"}, "--hello-timeout"},
      {{"--idle-timeout", "nan"}, "--idle-timeout"},
      {{"--player-idle", "-1"}, "--player-idle"},
      {{"--max-commands", "0"}, "--max-commands"},
      {{"--add-rights", "observers"}, "--add-rights must be players, everyone or nobody"},
      {{"--add-rate", "-5"}, "--add-rate"},
      {{"--no-such-flag"}, "no-such-flag"},
      // A flag whose value is forgotten would take the next flag as its value.
      {{"--record", "--bench"}, "--record wants a value, got the flag '--bench'"},
      {{"--dump", "--balls", "10"}, "--dump wants a value, got the flag '--balls'"},
      {{"--dt=--x"}, "--dt wants a value, got the flag '--x'"},
      // An empty name would write nothing.
      {{"--dump", ""}, "--dump needs a name, got an empty one"},
      {{"--record", ""}, "--record needs a name, got an empty one"},
      {{"--export-lammps", ""}, "--export-lammps needs a name, got an empty one"},
      {{"--bench", "--balls", "0"}, "--bench times balls: give --balls 1 or more"},
      // A flag of the other mode would go unused.
      {{"--steps", "100"}, "--steps shapes a benchmark: give --bench too, or drop it"},
      {{"--bench", "--port", "9000"}, "--port is for clients, and --bench runs without a network: drop it"},
      {{"--bench", "--max-connections", "5"}, "--max-connections is for clients"},
      {{"--bench", "--duration", "5"}, "--duration paces the server, and --bench runs unpaced for --steps"},
      {{"--web-root", "/nonexistent-folder"}, "--web-root /nonexistent-folder does not exist"},
  };
  for (const Bad& b : bad) {
    std::string line;
    for (const std::string& a : b.args) line += a + " ";
    INFO(line);
    const ParseResult r = parse(b.args);
    CHECK_FALSE(r.options);
    CHECK(r.exit_code == 2);
    CHECK(r.message.find(b.says) != std::string::npos);
    CHECK(r.message.rfind("fishtank-server: ", 0) == 0);
  }
}

TEST_CASE("the range ends the refusals state are accepted: k 784.8 and the shortest dt as printed", "[options]") {
  CHECK(parse({"--stiffness", "784.8"}).options);
  const ParseResult refused = parse({"--dt", "1e-8"});
  const std::string floor_said = "dt must be >= ";
  const std::size_t at = refused.message.find(floor_said);
  REQUIRE(at != std::string::npos);
  const std::string shortest =
      refused.message.substr(at + floor_said.size(), refused.message.find(" s", at) - at - floor_said.size());
  INFO("the refusal's floor: " << shortest);
  const ParseResult accepted = parse({"--dt", shortest});
  REQUIRE(accepted.options);
  CHECK(accepted.options->physics.dt == std::stof(shortest));
  CHECK(parse({"--dt", "0"}).options->physics.dt == 0.0f);  // automatic
}

TEST_CASE("the scalar build refuses more than one thread and says which build to use", "[options]") {
  CHECK(parse({}, "scalar", false).options->threads == 1);
  const ParseResult r = parse({"--threads", "2"}, "scalar", false);
  CHECK_FALSE(r.options);
  CHECK(r.exit_code == 2);
  CHECK(r.message.find("fishtank-server") != std::string::npos);
}

TEST_CASE("the web viewer's flags land where the network reads them", "[options]") {
  const std::string page = std::filesystem::temp_directory_path().string();  // a folder given must exist
  const ParseResult r = parse({"--web-port", "0", "--web-root", page});
  REQUIRE(r.options);
  CHECK(r.options->web);
  CHECK(r.options->web_port == 0);
  CHECK(r.options->web_root == page);
  const ParseResult off = parse({"--no-web"});
  REQUIRE(off.options);
  CHECK_FALSE(off.options->web);
}

TEST_CASE("the limits on clients land where the network reads them", "[options]") {
  const ParseResult r =
      parse({"--max-connections", "5", "--max-pending-per-address", "3", "--hello-timeout", "0.5", "--idle-timeout",
             "2", "--player-idle", "0", "--max-commands", "50", "--add-rights", "everyone", "--add-rate", "100"});
  REQUIRE(r.options);
  const net::ClientLimits& l = r.options->limits;
  CHECK(l.max_connections == 5);
  CHECK(l.max_pending_per_address == 3);
  CHECK(l.hello_timeout_s == 0.5);
  CHECK(l.idle_timeout_s == 2.0);
  CHECK(l.player_idle_s == 0.0);
  CHECK(l.max_commands_per_s == 50.0);
  CHECK(l.add_rights == net::AddRights::everyone);
  CHECK(l.add_balls_per_minute == 100.0);
  CHECK(parse({}).options->limits.add_rights == net::AddRights::players);
}
