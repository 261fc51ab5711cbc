#include "server_process.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace fishtank::test {

namespace {
using Clock = std::chrono::steady_clock;

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}
}  // namespace

ServerProcess::ServerProcess(const std::vector<std::string>& args, const std::vector<std::string>& launcher) {
  static int counter = 0;
  log_path_ = (std::filesystem::temp_directory_path() /
               ("fishtank-net-test-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + ".log"))
                  .string();
  // --duration: a server whose test was killed before its destructor ran still
  // stops by itself instead of running on as an orphan.
  std::vector<std::string> argv_text{FISHTANK_SERVER_PATH, "--bind", "127.0.0.1", "--port", "0", "--duration", "300"};
  // The server refuses a flag given twice.
  if (std::find(args.begin(), args.end(), "--threads") == args.end())
    argv_text.insert(argv_text.end(), {"--threads", "1"});
  // Tests run side by side: none may take the default web port.
  const bool web = std::find(args.begin(), args.end(), "--web-port") != args.end();
  if (!web) argv_text.push_back("--no-web");
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  argv_text.insert(argv_text.begin(), launcher.begin(), launcher.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&files, STDERR_FILENO, log_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  const int spawned = posix_spawn(&pid_, argv[0], &files, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  if (spawned != 0) throw std::runtime_error("cannot start " + argv_text[0]);

  const std::regex listening("listening on 127\\.0\\.0\\.1:([0-9]+)");
  const std::regex web_viewer("web viewer on http://127\\.0\\.0\\.1:([0-9]+)/");
  const Clock::time_point deadline = Clock::now() + std::chrono::seconds(15);
  while (Clock::now() < deadline && running()) {
    std::smatch m, w;
    const std::string text = log();
    if (std::regex_search(text, m, listening) && (!web || std::regex_search(text, w, web_viewer))) {
      port_ = static_cast<std::uint16_t>(std::stoi(m[1]));
      if (web) web_port_ = static_cast<std::uint16_t>(std::stoi(w[1]));
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  throw std::runtime_error("fishtank-server did not start listening; its log:\n" + log());
}

ServerProcess::~ServerProcess() {
  if (running()) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  std::error_code ignored;
  // scripts/test-asan: a server's sanitizer report fails the run even when the
  // test that started the server passed, so its log is kept for the script.
  if (const char* reports = std::getenv("FISHTANK_SANITIZER_REPORTS")) {
    const std::string text = log();
    if (text.find("runtime error:") != std::string::npos || text.find("Sanitizer") != std::string::npos)
      std::filesystem::copy_file(log_path_,
                                 std::filesystem::path(reports) / std::filesystem::path(log_path_).filename(),
                                 std::filesystem::copy_options::overwrite_existing, ignored);
  }
  std::filesystem::remove(log_path_, ignored);
}

bool ServerProcess::running() {
  if (reaped_) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) == pid_) {
    reaped_ = true;
    exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return false;
  }
  return true;
}

long ServerProcess::rss_kb() const {
  std::ifstream status("/proc/" + std::to_string(pid_) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return 0;
}

std::string ServerProcess::log() const { return read_file(log_path_); }

int ServerProcess::terminate() {
  if (!running()) return exit_status_;
  kill(pid_, SIGTERM);
  const Clock::time_point deadline = Clock::now() + std::chrono::seconds(10);
  while (Clock::now() < deadline && running()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (!reaped_) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    reaped_ = true;
    return -1;
  }
  return exit_status_;
}

RawSocket::RawSocket(std::uint16_t port, int receive_buffer) {
  fd_ = socket(AF_INET, SOCK_STREAM, 0);
  if (receive_buffer > 0) setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0)
    throw std::runtime_error("cannot connect to 127.0.0.1:" + std::to_string(port));
}

RawSocket::~RawSocket() { close(); }

void RawSocket::send(const std::vector<std::uint8_t>& bytes) {
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) throw std::runtime_error("send failed");
    sent += static_cast<std::size_t>(n);
  }
}

bool RawSocket::read_until_closed(std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  std::uint8_t buffer[65536];
  while (Clock::now() < deadline) {
    pollfd p{fd_, POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (poll(&p, 1, static_cast<int>(std::max<long>(1, left.count()))) <= 0) continue;
    const ssize_t n = recv(fd_, buffer, sizeof buffer, 0);
    if (n <= 0) return true;  // closed (or reset) by the server
    out.insert(out.end(), buffer, buffer + n);
  }
  return false;
}

bool RawSocket::read_until(const std::string& text, std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  std::uint8_t buffer[4096];
  while (std::search(out.begin(), out.end(), text.begin(), text.end()) == out.end()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd_, POLLIN, 0};
    if (poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
    const ssize_t n = recv(fd_, buffer, sizeof buffer, 0);
    if (n <= 0) return false;
    out.insert(out.end(), buffer, buffer + n);
  }
  return true;
}

void RawSocket::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

}  // namespace fishtank::test
