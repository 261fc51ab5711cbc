// fishtank-client: a scripted test and load client (see --help).

#include <algorithm>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "client/options.h"
#include "common/host_port.h"
#include "common/number_text.h"
#include "common/server_hint.h"

int main(int argc, char** argv) {
  const fishtank::client::ClientParse parsed = fishtank::client::parse_client_options(argc, argv);
  if (!parsed.options) {
    (parsed.exit_code == 0 ? std::cout : std::cerr) << parsed.message << "\n";
    return parsed.exit_code;
  }
  const fishtank::client::ClientOptions& o = *parsed.options;
  // Per ball per snapshot: what a snapshot costs, whatever the rate and the tank.
  const auto per_ball = [](double bytes, double snapshots, double balls) {
    return snapshots > 0.0 && balls > 0.0 ? bytes / (snapshots * balls) : 0.0;
  };
  const fishtank::client::Summary s =
      fishtank::client::run_script(o.script, [&](const fishtank::client::IntervalReport& r) {
        const double bytes_per_ball = per_ball(r.bytes, r.snapshots, r.balls);
        if (o.json)
          std::cout << nlohmann::json{{"t", r.t},
                                      {"balls", r.balls},
                                      {"snapshots", r.snapshots},
                                      {"keyframes", r.keyframes},
                                      {"bytes", r.bytes},
                                      {"bytes_per_ball", bytes_per_ball},
                                      {"rtt_ms", r.rtt_ms ? nlohmann::json(*r.rtt_ms) : nlohmann::json()}}
                           .dump()
                    << std::endl;
        else
          std::cout << "t " << r.t << " s: " << r.snapshots << " snapshots (" << r.keyframes << " in full), " << r.bytes
                    << " bytes, " << bytes_per_ball << " bytes per ball per snapshot, rtt "
                    << (r.rtt_ms ? fishtank::number_text(*r.rtt_ms) + " ms" : "(no Pong came back)") << "\n";
      });
  if (!s.connect_error.empty()) {
    const std::string advice =
        fishtank::connection_advice(o.script.host, std::to_string(o.script.port), s.connect_error);
    std::cerr << "fishtank-client: no connection to "
              << fishtank::host_port_text(o.script.host, std::to_string(o.script.port)) << ": " << s.connect_error
              << "." << (advice.empty() ? "" : " " + advice) << "\n";
    return 1;
  }
  const double bytes_per_ball = per_ball(s.bytes_per_s, s.snapshot_rate_hz, s.balls);
  const std::vector<std::string> errors = fishtank::client::each_once(s.error_messages);
  if (o.json) {
    nlohmann::json j = {{"clients", s.clients},
                        {"welcomed", s.welcomed},
                        {"players", s.players},
                        {"players_granted", s.players_granted},
                        {"snapshots", s.snapshots},
                        {"keyframes", s.keyframes},
                        {"snapshot_rate_hz", s.snapshot_rate_hz},
                        {"bytes_per_s", s.bytes_per_s},
                        {"bytes_per_ball", bytes_per_ball},
                        {"rtt_ms", s.rtt_ms},
                        {"balls", s.balls},
                        {"steps_per_s", s.steps_per_s},
                        {"load", s.load},
                        {"threads_stepping", s.threads_stepping},
                        {"worker_threads", s.worker_threads},
                        {"time_scale", s.time_scale},
                        {"time_scale_set", s.time_scale_set},
                        {"max_overlap", s.max_overlap},
                        {"paused", s.paused},
                        {"scene", s.scene},
                        {"scene_start", s.scene_start},
                        {"physics_steps", s.physics_steps},
                        {"at_rest_fraction", s.at_rest_fraction},
                        {"int8_delta_fraction", s.int8_delta_fraction},
                        {"dropped", s.dropped},
                        {"errors", s.error_messages.size()},
                        {"error_codes", s.error_codes},
                        {"error_messages", errors}};
    std::cout << j.dump() << std::endl;
  } else {
    std::cout << s.welcomed << " of " << s.clients << " clients welcomed (" << s.players << " with a player sphere"
              << (s.players_granted ? ", " + std::to_string(s.players_granted) + " given one another freed" : "")
              << "); " << s.snapshots << " snapshots (" << s.snapshot_rate_hz << " Hz and " << s.bytes_per_s / 1e3
              << " kB/s per client); rtt " << s.rtt_ms << " ms; " << s.balls << " balls; server "
              << std::lround(s.steps_per_s) << " steps/s, load " << std::lround(100.0 * s.load) << " % on "
              << s.threads_stepping << " of " << s.worker_threads << " threads, time scale " << s.time_scale << " (set "
              << s.time_scale_set << "); scene " << s.scene << (s.paused ? ", paused" : "") << "\n";
    for (const std::string& e : errors) std::cout << "error: " << e << "\n";
  }
  if (s.welcomed < s.clients) {
    std::cerr << "fishtank-client: " << s.clients - s.welcomed << " of " << s.clients
              << " connections were not welcomed (the server's reasons are above)\n";
    return 1;
  }
  if (s.dropped > 0) {
    const bool stopped =
        std::find(s.error_codes.begin(), s.error_codes.end(), "server_stopping") != s.error_codes.end();
    std::cerr << "fishtank-client: " << (stopped ? "the server stopped, ending " : "the server dropped ") << s.dropped
              << " of " << s.clients << " connections before --duration ended\n";
    return 1;
  }
  // player_limit and player_idle only say a client observes (in line, or its unmoved sphere freed); any
  // other Error refused what was asked.
  if (std::any_of(s.error_codes.begin(), s.error_codes.end(),
                  [](const std::string& c) { return c != "player_limit" && c != "player_idle"; })) {
    std::cerr << "fishtank-client: the server refused what was asked (its reasons are above)\n";
    return 1;
  }
  return 0;
}
