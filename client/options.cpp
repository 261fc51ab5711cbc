#include "client/options.h"

#include <boost/program_options.hpp>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/flag_values.h"
#include "common/host_port.h"
#include "common/number_text.h"
#include "common/pending_connections.h"
#include "common/scene_names.h"
#include "protocol/frame_codec.h"

namespace fishtank::client {

namespace po = boost::program_options;

namespace {

// "x,y,z" with three finite numbers and nothing else.
std::optional<Vec3> parse_vec3(const std::string& text) {
  Vec3 v;
  int consumed = 0;
  if (std::sscanf(text.c_str(), "%f,%f,%f%n", &v.x, &v.y, &v.z, &consumed) != 3) return std::nullopt;
  if (static_cast<std::size_t>(consumed) != text.size() || !is_finite(v)) return std::nullopt;
  return v;
}

}  // namespace

ClientParse parse_client_options(int argc, const char* const argv[]) {
  ClientOptions o;
  std::string connect = "127.0.0.1:7878", move;
  std::int64_t clients = 1, add = 0, step = 0, seed = -1, max_pending = kDefaultMaxPendingPerAddress;
  std::string scene;
  float time_scale = 0.0f;
  bool reset = false, pause = false, resume = false;
  bool no_ack = false;
  double read_rate_kb = 0.0;

  po::options_description flags("Options");
  flags.add_options()("help,h", "print this help and exit")("connect", po::value(&connect)->default_value(connect),
                                                            "server address, host:port")(
      "clients", po::value(&clients)->default_value(clients), "concurrent connections, 1 .. 1000")(
      "max-pending", po::value(&max_pending)->default_value(max_pending),
      "connections waiting for their Welcome at once, 1 .. 1000: at most the server's --max-pending-per-address")(
      "observer", po::bool_switch(&o.script.observer), "ask for no player sphere")(
      "no-ack", po::bool_switch(&no_ack),
      "never acknowledge snapshots, so that the server sends each in full instead of a delta")(
      "read-rate", po::value(&read_rate_kb)->default_value(0.0),
      "kB a second each connection reads at most, as over a slow link (a phone on a busy Wi-Fi); 0: no limit")(
      "add", po::value(&add)->default_value(0), "balls the first client asks the server to pour in")(
      "move", po::value(&move), "player sphere velocity x,y,z in m/s (every client with a sphere)")(
      "for", po::value(&o.script.move_for)->default_value(o.script.move_for), "seconds to move before stopping")(
      "duration", po::value(&o.script.duration)->default_value(o.script.duration), "seconds to stay connected")(
      "every", po::value(&o.script.every)->default_value(0.0),
      "also report what was received every this many seconds (0: only the summary)")(
      "json", po::bool_switch(&o.json), "print one JSON summary on stdout (and one JSON line per --every interval)");
  po::options_description controls(
      "Sandbox controls (sent once by the first client; the server's --control says who may)");
  controls.add_options()("scene", po::value(&scene), "start this scene: tank, wide, dam-break or drop")(
      "reset", po::bool_switch(&reset), "start the scene running again")(
      "seed", po::value(&seed), "random seed for --reset or --scene, >= 0 (default: the scene's last)")(
      "time-scale", po::value(&time_scale), "simulated seconds per wall second, 0.1 .. 1")(
      "pause", po::bool_switch(&pause), "pause the simulation")("resume", po::bool_switch(&resume),
                                                                "resume a paused simulation")(
      "step", po::value(&step)->default_value(0), "steps to run while paused (with --pause, or on a paused server)");
  flags.add(controls);

  ClientParse result;
  auto fail = [&result](const std::string& why) {
    result.exit_code = 2;
    result.message = "fishtank-client: " + why + "\nTry --help for the list of options.";
    return result;
  };
  po::variables_map vm;
  try {
    po::store(parse_flags(argc, argv, flags), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    return fail(flag_error_text(e, flags));
  }
  if (vm.count("help")) {
    std::ostringstream help;
    help << "fishtank-client: connects to a fishtank-server, runs a short script and reports what it received.\n\n"
         << "Usage: fishtank-client [--connect host:port] [--clients K [--max-pending N]] [--observer] [--no-ack]\n"
         << "                       [--read-rate KB]\n"
         << "                       [--add N] [--move x,y,z --for T] [--duration T] [--every T] [--json]\n"
         << "                       [--scene NAME | --reset] [--seed S] [--time-scale X] [--pause | --resume] [--step "
            "N]\n\n"
         << "Example: fishtank-client --clients 8 --add 1000 --move 2,0,0 --for 1 --duration 5 --json\n"
         << "         fishtank-client --scene drop --seed 3 --pause --step 500 --duration 2 --json\n\n"
         << flags;
    result.message = help.str();
    return result;
  }
  const auto address = parse_host_port(connect);
  if (!address) return fail("--connect wants host:port with a port 1 .. 65535, got '" + connect + "'");
  o.script.host = address->host;
  o.script.port = address->port;
  if (clients < 1 || clients > 1000)
    return fail("--clients must be between 1 and 1000, got " + std::to_string(clients));
  if (max_pending < 1 || max_pending > 1000)
    return fail("--max-pending must be between 1 and 1000, got " + std::to_string(max_pending));
  if (add < 0 || add > protocol::kMaxAddBallsPerRequest)
    return fail("--add must be between 0 and " + std::to_string(protocol::kMaxAddBallsPerRequest) + ", got " +
                std::to_string(add));
  if (!vm["move"].empty()) {
    o.script.move = parse_vec3(move);
    if (!o.script.move) return fail("--move wants three finite numbers x,y,z, got '" + move + "'");
    if (o.script.observer) return fail("--move needs a player sphere; drop --observer");
  }
  if (!std::isfinite(o.script.move_for) || o.script.move_for < 0.0)
    return fail("--for must be seconds >= 0, got " + number_text(o.script.move_for));
  if (!std::isfinite(o.script.duration) || o.script.duration <= 0.0 || o.script.duration > 86400.0)
    return fail("--duration must be more than 0 and at most 86400 seconds, got " + number_text(o.script.duration));
  if (!std::isfinite(o.script.every) || o.script.every < 0.0 ||
      (o.script.every > 0.0 && o.script.every < kShortestEvery))
    return fail("--every must be 0 (no interval reports) or at least " + number_text(kShortestEvery) +
                " s, the client's tick, got " + number_text(o.script.every));
  if (!std::isfinite(read_rate_kb) || read_rate_kb < 0.0 || (read_rate_kb > 0.0 && read_rate_kb < 1.0))
    return fail("--read-rate must be 0 (no limit) or at least 1 kB a second, got " + number_text(read_rate_kb));
  if (pause && resume) return fail("--pause and --resume contradict each other; give one");
  if (step < 0 || step > protocol::kMaxStepsPerRequest)
    return fail("--step must be between 0 and " + std::to_string(protocol::kMaxStepsPerRequest) + ", got " +
                std::to_string(step));
  if (!vm["time-scale"].empty() && !(time_scale >= protocol::kMinTimeScale && time_scale <= protocol::kMaxTimeScale))
    return fail("--time-scale must be between 0.1 and 1, got " + number_text(time_scale));
  if (!vm["scene"].empty() && !is_scene_name(scene))
    return fail("--scene: unknown scene '" + scene + "'; the scenes are " + scene_names_text());
  if (!vm["scene"].empty() && reset) return fail("--scene starts that scene from its start already; drop --reset");
  if (!vm["for"].defaulted() && vm["move"].empty()) return fail("--for goes with --move (how long to move)");
  if (!vm["seed"].empty() && seed < 0) return fail("--seed must be >= 0, got " + std::to_string(seed));
  if (!vm["seed"].empty() && vm["scene"].empty() && !reset) return fail("--seed goes with --reset or --scene");
  if (!vm["scene"].empty()) o.script.scene = scene;
  if (!vm["seed"].empty()) o.script.seed = static_cast<std::uint64_t>(seed);
  if (!vm["time-scale"].empty()) o.script.time_scale = time_scale;
  if (pause || resume) o.script.pause = pause;
  o.script.reset = reset;
  o.script.step = static_cast<std::uint32_t>(step);
  o.script.clients = static_cast<int>(clients);
  o.script.max_pending = static_cast<std::size_t>(max_pending);
  o.script.acknowledge = !no_ack;
  o.script.read_rate = 1e3 * read_rate_kb;
  o.script.add = static_cast<std::uint32_t>(add);
  result.options = o;
  return result;
}

}  // namespace fishtank::client
