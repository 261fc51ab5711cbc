#include "client/script.h"

#include <algorithm>
#include <boost/asio.hpp>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <utility>

#include "client/connection.h"
#include "common/number_text.h"
#include "common/server_hint.h"

namespace fishtank::client {

namespace asio = boost::asio;
using Clock = std::chrono::steady_clock;

namespace {

const auto kTick = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kShortestEvery));
constexpr int kTicksPerPing = 5;
// While connections are still to open: how often to look whether one more may wait for its Welcome.
constexpr auto kRampTick = std::chrono::milliseconds(1);

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The median of values (reordered); 0 when there are none.
double median(std::vector<double>& values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

Summary summarise(const std::vector<std::shared_ptr<Connection>>& connections, double seconds) {
  Summary s;
  s.clients = static_cast<int>(connections.size());
  std::vector<double> rtts;
  std::uint32_t newest_tick = 0;
  int rated = 0;  // connections the rates are a mean over
  for (const auto& c : connections) {
    const ConnectionStats& st = c->stats();
    s.welcomed += c->welcomed();
    s.players += c->player_id().has_value();
    s.players_granted += st.player_granted;
    s.snapshots += st.snapshots;
    s.keyframes += st.keyframes;
    // Rates over the span a connection received snapshots, where that covers a quarter of the run: a connection
    // opened late, or whose snapshots came in one burst (a client busier than the server), gives none.
    const double span =
        st.snapshots >= 2 ? std::chrono::duration<double>(*st.last_snapshot - *st.first_snapshot).count() : 0.0;
    if (span >= 0.25 * seconds) {
      ++rated;
      s.snapshot_rate_hz += (st.snapshots - 1) / span;
      s.bytes_per_s += st.bytes_received / span;
    }
    rtts.insert(rtts.end(), st.rtt_ms.begin(), st.rtt_ms.end());
    s.error_messages.insert(s.error_messages.end(), st.errors.begin(), st.errors.end());
    for (const std::string& code : st.error_codes)
      if (std::find(s.error_codes.begin(), s.error_codes.end(), code) == s.error_codes.end())
        s.error_codes.push_back(code);
    if (st.snapshots > 0 && c->view().tick >= newest_tick) {
      newest_tick = c->view().tick;
      s.balls = c->view().ball_count;
      s.steps_per_s = c->view().steps_per_s;
      s.load = c->view().load;
      s.threads_stepping = c->view().threads_stepping;
      s.time_scale = shortest_decimal(c->view().time_scale);  // 0.1 as set, not the float widened
      s.time_scale_set = shortest_decimal(c->view().time_scale_set);
      s.max_overlap = c->view().max_overlap;
      s.paused = c->view().paused;
      s.scene = c->view().scene;
      s.scene_start = c->view().scene_start;
      s.physics_steps = c->view().physics_steps;
      s.worker_threads = c->worker_threads();
      s.at_rest_fraction = st.at_rest_fraction;
      s.int8_delta_fraction = st.int8_delta_fraction;
    }
    if (!c->welcomed() && !c->close_reason().empty()) s.error_messages.push_back("connection: " + c->close_reason());
  }
  if (rated > 0) {
    s.snapshot_rate_hz /= rated;
    s.bytes_per_s /= rated;
  }
  s.rtt_ms = median(rtts);
  return s;
}

// The sandbox's controls the script asks for, in the order they are sent.
std::vector<protocol::Frame> control_frames(const Script& script) {
  std::vector<protocol::Frame> frames;
  if (script.scene || script.reset) frames.push_back(protocol::encode_reset(script.scene.value_or(""), script.seed));
  if (script.time_scale) frames.push_back(protocol::encode_set_time_scale(*script.time_scale));
  if (script.pause) frames.push_back(protocol::encode_pause(*script.pause));
  if (script.step > 0) frames.push_back(protocol::encode_step(script.step));
  return frames;
}

}  // namespace

std::vector<std::string> each_once(const std::vector<std::string>& messages) {
  std::vector<std::pair<std::string, int>> counted;
  for (const std::string& m : messages) {
    const auto same = std::find_if(counted.begin(), counted.end(), [&](const auto& seen) { return seen.first == m; });
    if (same == counted.end())
      counted.emplace_back(m, 1);
    else
      ++same->second;
  }
  std::vector<std::string> out;
  for (const auto& [m, count] : counted)
    out.push_back(count > 1 ? m + " (" + std::to_string(count) + " connections)" : m);
  return out;
}

Summary run_script(const Script& script, const std::function<void(const IntervalReport&)>& on_interval) {
  asio::io_context io;
  boost::system::error_code ec;
  asio::ip::tcp::resolver resolver(io);
  const auto resolved = resolver.resolve(script.host, std::to_string(script.port), ec);
  if (ec || resolved.empty()) {
    Summary failed;
    failed.connect_error = cannot_resolve_text(script.host, ec.message());
    return failed;
  }
  const asio::ip::tcp::endpoint server = *resolved.begin();

  std::vector<std::shared_ptr<Connection>> connections;
  for (int i = 0; i < script.clients; ++i) {
    connections.push_back(
        std::make_shared<Connection>(io, "fishtank-client-" + std::to_string(i + 1), !script.observer));
    connections.back()->acknowledge_snapshots(script.acknowledge);
    connections.back()->limit_read_rate(script.read_rate);
  }
  // Opened a few at a time (--max-pending): all at once, a server's --max-pending-per-address would evict most of
  // them as a stranger's stalled connections before their Hello is read.
  std::size_t opened = 0;
  bool ended = false;  // --duration is over: a ramp tick already due opens nothing more
  asio::steady_timer ramp(io);
  std::function<void()> open_more = [&] {
    if (ended) return;
    std::size_t waiting = 0;
    for (std::size_t i = 0; i < opened; ++i) waiting += !connections[i]->welcomed() && !connections[i]->closed();
    for (; opened < connections.size() && waiting < script.max_pending; ++opened, ++waiting)
      connections[opened]->start(server);
    if (opened == connections.size()) return;
    ramp.expires_after(kRampTick);
    ramp.async_wait([&](boost::system::error_code e) {
      if (!e) open_more();
    });
  };
  open_more();

  const Clock::time_point start = Clock::now();
  bool added = false;  // the controls and --add were sent
  // Per connection: 0 not moving yet, 1 moving, 2 stopped after --for seconds.
  std::vector<int> move_phase(connections.size(), 0);
  int tick = 0;
  asio::steady_timer timer(io);
  std::vector<double> dropped_at(connections.size(), -1.0);  // seconds; -1 while open
  IntervalReport reported;                                   // the totals at the last report
  std::vector<std::size_t> pongs_reported(connections.size(), 0);
  const auto report_interval = [&](double t) {
    IntervalReport now;
    now.t = t;
    std::vector<double> rtts;
    for (std::size_t i = 0; i < connections.size(); ++i) {
      const ConnectionStats& st = connections[i]->stats();
      now.snapshots += st.snapshots;
      now.keyframes += st.keyframes;
      now.bytes += st.bytes_received;
      now.balls = std::max(now.balls, connections[i]->view().ball_count);
      rtts.insert(rtts.end(), st.rtt_ms.begin() + pongs_reported[i], st.rtt_ms.end());
      pongs_reported[i] = st.rtt_ms.size();
    }
    on_interval({now.t, now.balls, now.snapshots - reported.snapshots, now.keyframes - reported.keyframes,
                 now.bytes - reported.bytes, rtts.empty() ? std::nullopt : std::optional(median(rtts))});
    reported = now;
  };
  std::function<void()> on_tick = [&] {
    const double t = seconds_since(start);
    if (t >= script.duration) {
      ended = true;
      ramp.cancel();
      for (std::size_t i = 0; i < opened; ++i) {
        if (connections[i]->welcomed())
          connections[i]->close();
        else
          connections[i]->close("--duration ended before its Welcome");
      }
      return;
    }
    if (script.every > 0.0 && on_interval && t >= reported.t + script.every) report_interval(t);
    for (std::size_t i = 0; i < connections.size(); ++i)
      if (dropped_at[i] < 0.0 && connections[i]->closed()) dropped_at[i] = t;
    if (std::all_of(dropped_at.begin(), dropped_at.end(), [](double d) { return d >= 0.0; })) return;  // all gone
    if (!added && connections.front()->welcomed()) {
      for (protocol::Frame& frame : control_frames(script)) connections.front()->send(std::move(frame));
      if (script.add > 0) connections.front()->send(protocol::encode_add_balls(script.add));
      added = true;
    }
    for (std::size_t i = 0; script.move && i < connections.size(); ++i) {
      if (!connections[i]->player_id()) continue;
      if (move_phase[i] == 0) {
        connections[i]->send(protocol::encode_player_input(1, *script.move));
        move_phase[i] = 1;
      } else if (move_phase[i] == 1 && t >= script.move_for) {
        connections[i]->send(protocol::encode_player_input(2, {0.0f, 0.0f, 0.0f}));
        move_phase[i] = 2;
      }
    }
    if (tick++ % kTicksPerPing == 0)
      for (auto& c : connections)
        if (c->welcomed()) c->send_ping();
    timer.expires_after(kTick);
    timer.async_wait([&](boost::system::error_code e) {
      if (!e) on_tick();
    });
  };
  on_tick();
  io.run();

  // Rates over the time the script ran: a dropped connection's snapshots do not read as a live rate.
  Summary summary = summarise(connections, std::max(std::min(script.duration, seconds_since(start)), 1e-3));
  for (std::size_t i = 0; i < connections.size(); ++i) {
    if (dropped_at[i] < 0.0 || !connections[i]->welcomed()) continue;
    ++summary.dropped;
    summary.error_messages.push_back("dropped by the server after " + std::to_string(std::lround(dropped_at[i])) +
                                     " s: " + connections[i]->close_reason());
  }
  if (opened < connections.size())
    summary.error_messages.push_back(
        std::to_string(connections.size() - opened) + " connections not opened: --duration ended while earlier ones " +
        "waited for their Welcome (--max-pending " + std::to_string(script.max_pending) + ")");
  if (summary.welcomed == 0 && !connections.empty()) summary.connect_error = connections.front()->close_reason();
  return summary;
}

}  // namespace fishtank::client
