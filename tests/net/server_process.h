#pragma once
// A real fishtank-server as a child process on an ephemeral 127.0.0.1 port,
// for the network tests. Its stderr goes to a temporary file, which is how
// the port is learnt ("listening on 127.0.0.1:PORT") and the log is checked.
// Its web viewer is off (--no-web) unless the args give --web-port: then its
// port, ephemeral with --web-port 0, is learnt from "web viewer on http://...".

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace fishtank::test {

class ServerProcess {
 public:
  // Starts fishtank-server --bind 127.0.0.1 --port 0 plus `args` (and --threads 1
  // unless they give --threads), and waits (at most 15 s) until it listens. Throws when it does not.
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
  // SIGTERM, then waits at most 10 s; the exit status, or -1 when it had to be killed.
  int terminate();

 private:
  pid_t pid_ = -1;
  std::string log_path_;
  std::uint16_t port_ = 0;
  std::uint16_t web_port_ = 0;
  bool reaped_ = false;
  int exit_status_ = -1;
};

// A plain blocking socket to 127.0.0.1, for bytes no well-behaved client sends.
class RawSocket {
 public:
  // receive_buffer > 0 shrinks the kernel's receive buffer before connecting.
  explicit RawSocket(std::uint16_t port, int receive_buffer = 0);
  ~RawSocket();
  RawSocket(const RawSocket&) = delete;
  RawSocket& operator=(const RawSocket&) = delete;

  void send(const std::vector<std::uint8_t>& bytes);
  void send_text(const std::string& text) { send(std::vector<std::uint8_t>(text.begin(), text.end())); }
  // Reads until what was read contains `text` (true) or `timeout` passes or the peer closes (false).
  bool read_until(const std::string& text, std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout);
  // Reads until the peer closes or `timeout` passes; true when it closed.
  bool read_until_closed(std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout);
  void close();

 private:
  int fd_ = -1;
};

}  // namespace fishtank::test
