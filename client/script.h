#pragma once
// A scripted session against a server: K connections on one thread, each says
// Hello; the first sends the sandbox's controls (scene or reset, time scale,
// pause or resume, step: in that order) and then asks for --add balls; those with a player sphere move it at
// --move for --for seconds; every connection pings four times a second; after
// --duration seconds everything is summed up.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/pending_connections.h"
#include "common/vec3.h"

namespace fishtank::client {

// The client looks at its connections (and reports an interval) this often.
inline constexpr double kShortestEvery = 0.05;

struct Script {
  std::string host = "127.0.0.1";
  std::uint16_t port = 7878;
  int clients = 1;
  // Connections waiting for their Welcome at once: a server evicts those beyond its --max-pending-per-address.
  std::size_t max_pending = kDefaultMaxPendingPerAddress;
  bool observer = false;
  bool acknowledge = true;  // false (--no-ack): every snapshot comes in full
  double read_rate = 0.0;   // bytes a second each connection reads at most (--read-rate); 0: no limit
  std::uint32_t add = 0;
  std::optional<Vec3> move;
  double move_for = 1.0;  // seconds
  double duration = 3.0;  // seconds
  // The sandbox's controls, sent once by the first connection.
  std::optional<std::string> scene;   // Reset to this scene
  bool reset = false;                 // Reset the scene running (when no scene is given)
  std::optional<std::uint64_t> seed;  // of the reset or scene
  std::optional<float> time_scale;
  std::optional<bool> pause;  // true: Pause, false: resume
  std::uint32_t step = 0;     // steps to run while paused
  double every = 0.0;         // seconds between interval reports, at least kShortestEvery; 0: none
};

// What every connection received in one --every interval, summed.
struct IntervalReport {
  double t = 0.0;           // seconds since the start, at the end of the interval
  std::uint32_t balls = 0;  // in the newest snapshot
  std::uint64_t snapshots = 0, keyframes = 0, bytes = 0;
  std::optional<double> rtt_ms;  // median of the Pongs that came back in the interval; empty: none did
};

struct Summary {
  int clients = 0;
  int welcomed = 0;
  int players = 0;              // connections holding a player sphere at the end
  int players_granted = 0;      // connections that waited in line and were given a sphere another freed
  std::uint64_t snapshots = 0;  // total over all clients
  std::uint64_t keyframes = 0;  // of those, the ones sent in full (the rest were deltas)
  // Means over the connections that received snapshots for a quarter of the run or more, each over that span.
  double snapshot_rate_hz = 0.0;
  double bytes_per_s = 0.0;
  double rtt_ms = 0.0;      // median over every Pong; 0 without any
  std::uint32_t balls = 0;  // newest ball count seen
  // The server's figures in that newest snapshot, and Welcome's worker threads.
  double steps_per_s = 0.0;
  double load = 0.0;
  std::uint32_t threads_stepping = 0;  // 0: not reported
  std::uint32_t worker_threads = 0;
  double time_scale = 0.0;      // simulated seconds per wall second; 0: not reported
  double time_scale_set = 0.0;  // asked for; 0: not reported
  double max_overlap = 0.0;     // largest overlap, a fraction of the smaller radius
  bool paused = false;
  std::string scene;
  std::uint32_t scene_start = 0;
  std::uint32_t physics_steps = 0;
  double at_rest_fraction = 0.0;     // in that newest snapshot (ConnectionStats::at_rest_fraction)
  double int8_delta_fraction = 0.0;  // likewise (ConnectionStats::int8_delta_fraction)
  std::vector<std::string> error_messages;
  std::vector<std::string> error_codes;  // the server's Error codes, each once, in the order first seen
  std::string connect_error;             // non-empty when no connection could be made
  // Connections the server closed before --duration was up (each also has an
  // error message saying why); the script ends early once all are closed.
  int dropped = 0;
};

// Each message once, in the order first seen, with how many connections got it
// ("... (12 connections)"): 12 observers beyond --max-players say the same.
std::vector<std::string> each_once(const std::vector<std::string>& messages);

// on_interval is called every script.every seconds (when that is > 0).
Summary run_script(const Script& script, const std::function<void(const IntervalReport&)>& on_interval = {});

}  // namespace fishtank::client
