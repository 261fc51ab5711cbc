#include "server/net/network_service.h"

#include <pthread.h>
#include <time.h>

#include <boost/asio/ip/host_name.hpp>
#include <csignal>
#include <cstdio>
#include <cstring>

#include "common/cpu_clock.h"
#include "server/net/machine_addresses.h"

namespace fishtank::net {

namespace {

double cpu_seconds_of(std::thread& thread) {
  clockid_t clock;
  return pthread_getcpuclockid(thread.native_handle(), &clock) == 0 ? cpu_seconds(clock) : 0.0;
}

}  // namespace

NetworkService::NetworkService(const NetOptions& options, ServerInfo info, RunControl& control, ActiveScene& scene,
                               std::atomic<bool>& stop)
    : options_(options),
      work_(boost::asio::make_work_guard(io_)),
      signals_(io_, SIGINT, SIGTERM),
      server_(io_, std::move(info), commands_),
      link_(
          commands_, server_.viewers(), options.link, control, scene,
          [this](Reply reply) { server_.post_reply(std::move(reply)); },
          [this](SharedSnapshot snapshot) { server_.post_snapshot(std::move(snapshot)); }) {
  signals_.async_wait([this, &stop](boost::system::error_code ec, int first) {
    if (ec) return;
    stop = true;
    await_second_signal(first);
  });
}

// The set keeps the signals until the server ends, so a second one must be heard here: while the final
// files are written (a huge --dump), the same signal again ends the process at once. Another one passes:
// a script's SIGTERM after the terminal's SIGINT (scripts/run's exit trap) must let the files be written.
void NetworkService::await_second_signal(int first) {
  signals_.async_wait([this, first](boost::system::error_code ec, int signal) {
    if (ec) return;
    if (signal != first) return await_second_signal(first);
    std::fprintf(stderr,
                 "fishtank-server: %s again: stopping at once; output files not finished are left as they are\n",
                 signal == SIGINT ? "interrupted" : "terminated");
    std::_Exit(128 + signal);
  });
}

std::string NetworkService::start() {
  if (std::string error = server_.listen(options_.bind, options_.port); !error.empty()) return error;
  if (options_.web) {
    if (std::string error = server_.listen_web(options_.bind, options_.web_port, options_.web_root); !error.empty())
      return error;
    if (!server_.static_files()->page_built())
      std::fprintf(stderr,
                   "the browser viewer's page is not built in %s: /ws works, and a browser gets a page saying "
                   "how to build it (or use --web-root DIR)\n",
                   options_.web_root.c_str());
  }
  const auto endpoint = server_.local_endpoint();
  // Tests and scripts parse these lines to find an ephemeral port.
  std::fprintf(stderr, "listening on %s:%u\n", url_host(endpoint.address()).c_str(), endpoint.port());
  if (options_.web) {
    const auto web = server_.web_endpoint();
    std::fprintf(stderr, "web viewer on http://%s:%u/\n", url_host(web.address()).c_str(), web.port());
  }
  // 0.0.0.0 is no address to give a room: an address of this machine's is (its name, where a name server knows it).
  if (endpoint.address().is_unspecified()) {
    const auto addresses = machine_addresses(endpoint.address().is_v6());
    std::string known_as = boost::asio::ip::host_name();
    for (const auto& address : addresses) known_as += ", " + address.to_string();
    const std::string host = addresses.empty() ? boost::asio::ip::host_name() : url_host(addresses.front());
    std::fprintf(stderr, "from other machines:");
    if (options_.web) std::fprintf(stderr, " a browser at http://%s:%u/,", host.c_str(), server_.web_endpoint().port());
    std::fprintf(stderr, " fishtank-viewer --connect %s:%u (this machine: %s)\n", host.c_str(), endpoint.port(),
                 known_as.c_str());
  }
  std::fflush(stderr);
  io_thread_ = std::thread([this] { io_.run(); });
  // Named, so that top -H and scripts/figures-web can tell its CPU time from the physics'.
  pthread_setname_np(io_thread_.native_handle(), "fishtank-io");
  return {};
}

void NetworkService::stop(const std::string& why) {
  boost::asio::post(io_, [this, why] { server_.stop(why); });
}

NetworkService::~NetworkService() {
  boost::asio::post(io_, [this] {
    server_.stop("it is shutting down");  // where stop() was not called first
    signals_.cancel();
    work_.reset();
  });
  // io_.run() returns once the last session has closed.
  if (io_thread_.joinable()) io_thread_.join();
}

std::string NetworkService::status() {
  const auto now = std::chrono::steady_clock::now();
  const double window = std::chrono::duration<double>(now - last_status_).count();
  const std::uint64_t bytes = server_.total_bytes_sent();
  const std::uint64_t skipped = server_.total_snapshots_skipped();
  const double io_cpu = io_thread_.joinable() ? cpu_seconds_of(io_thread_) : 0.0;
  const double process_cpu = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID);
  const SnapshotStats& snapshots = link_.snapshot_stats();
  const FrameStats& frames = server_.frame_stats();
  const std::uint64_t frames_coded = frames.frames.load(std::memory_order_relaxed);
  const std::uint64_t keyframes = frames.keyframes.load(std::memory_order_relaxed);
  const double coding_seconds = 1e-9 * static_cast<double>(frames.coding_ns.load(std::memory_order_relaxed));
  const std::uint64_t frame_bytes = frames.frame_bytes.load(std::memory_order_relaxed);

  // Networking = the io thread (which codes the frames) plus the capture on the physics thread, in CPU time
  // both: the capture's wall time also counts the moments a busy machine kept the thread waiting.
  const double net_cpu = (io_cpu - last_io_cpu_) + (snapshots.encode_cpu_seconds - last_encode_cpu_seconds_);
  const double process = process_cpu - last_process_cpu_;
  const std::uint64_t encoded = snapshots.encoded - last_encoded_;
  const std::uint64_t coded = frames_coded - last_frames_;
  // Per snapshot: its capture, plus every frame coded from it (one per distinct acknowledged base).
  const double encode_us =
      encoded ? 1e6 * ((snapshots.encode_seconds - last_encode_seconds_) + (coding_seconds - last_coding_seconds_)) /
                    encoded
              : 0.0;
  char line[400];
  std::snprintf(line, sizeof line,
                "clients %d  out %.2f MB/s  net cpu %.1f %% of process  snapshot %.0f us to encode, %.2f frames of "
                "%.0f B mean, %llu keyframes",
                server_.clients(), window > 0.0 ? (bytes - last_bytes_) / window / 1e6 : 0.0,
                process > 0.0 ? 100.0 * net_cpu / process : 0.0, encode_us,
                encoded ? static_cast<double>(coded) / encoded : 0.0,
                coded ? static_cast<double>(frame_bytes - last_frame_bytes_) / coded : 0.0,
                static_cast<unsigned long long>(keyframes - last_keyframes_));
  // Only while some client cannot take every snapshot: a slow link, or a reader busier than the server.
  if (skipped > last_skipped_ && window > 0.0)
    std::snprintf(line + std::strlen(line), sizeof line - std::strlen(line),
                  ", %.0f snapshots/s skipped for slow clients", (skipped - last_skipped_) / window);

  last_status_ = now;
  last_bytes_ = bytes;
  last_skipped_ = skipped;
  last_io_cpu_ = io_cpu;
  last_process_cpu_ = process_cpu;
  last_encode_seconds_ = snapshots.encode_seconds;
  last_encode_cpu_seconds_ = snapshots.encode_cpu_seconds;
  last_encoded_ = snapshots.encoded;
  last_frames_ = frames_coded;
  last_keyframes_ = keyframes;
  last_coding_seconds_ = coding_seconds;
  last_frame_bytes_ = frame_bytes;
  return line;
}

}  // namespace fishtank::net
