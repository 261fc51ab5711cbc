#pragma once
// A real fishtank-server as a child process on an ephemeral 127.0.0.1 port,
// for the network tests. Its stderr goes to a temporary file, which is how
// the port is learnt ("listening on 127.0.0.1:PORT") and the log is checked.
// Its web viewer is off (--no-web) unless the args give --web-port: then its
// port, ephemeral with --web-port 0, is learnt from "web viewer on http://...".

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

// Its users drive the server with raw bytes too: they get RawSocket from here.
#include "raw_socket.h"

namespace fishtank::test {

// Polls done() every `poll` until it holds (true) or `timeout` passes (false).
bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout,
                std::chrono::milliseconds poll = std::chrono::milliseconds(50));

class ServerProcess {
 public:
  // Starts fishtank-server --bind 127.0.0.1 --port 0 plus `args` (and --threads 1
  // unless they give --threads), and waits (at most 15 s) until it listens. Throws when it does not,
  // leaving neither the server running nor its log behind.
  // `launcher` goes before the server's path, e.g. {"/usr/bin/prlimit", "--nofile=40", "--"}.
  explicit ServerProcess(const std::vector<std::string>& args, const std::vector<std::string>& launcher = {});
  // SIGKILL if still running.
  ~ServerProcess();
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  std::uint16_t port() const { return port_; }
  std::uint16_t web_port() const { return web_port_; }  // 0 without --web-port
  bool running();
  // Resident memory of the server now, in kB (0 when unknown).
  long rss_kb() const;
  std::string log() const;
  // Waits (at most `timeout`) until the log has `text`; false when it did not come.
  bool wait_for_log(const std::string& text, std::chrono::milliseconds timeout) const;
  // SIGTERM, without waiting: the server tells its clients why and ends (terminate() then waits).
  void request_stop();
  // SIGTERM unless request_stop() sent it (a second one stops at once), then waits at most 10 s;
  // the exit status, or -1 when it had to be killed.
  int terminate();

 private:
  // Until the log shows the port(s) listening; throws when the server exits or 15 s pass.
  void wait_until_listening(bool web);
  // SIGKILL and reap the server if it runs, then remove its log (first copied for
  // scripts/test-asan when it holds a sanitizer report).
  void discard();

  pid_t pid_ = -1;
  std::string log_path_;
  std::uint16_t port_ = 0;
  std::uint16_t web_port_ = 0;
  bool reaped_ = false;
  bool stop_requested_ = false;
  int exit_status_ = -1;
};

}  // namespace fishtank::test
