#include "server_process.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
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

bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout, std::chrono::milliseconds poll) {
  const Clock::time_point deadline = Clock::now() + timeout;
  while (!done()) {
    if (Clock::now() > deadline) return false;
    std::this_thread::sleep_for(poll);
  }
  return true;
}

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
  if (spawned != 0) {
    pid_ = -1;  // unspecified on failure; discard() must not signal it
    discard();  // the child may have created the log before its exec failed
    throw std::runtime_error("cannot start " + argv_text[0]);
  }
  // A throwing constructor runs no destructor: without this a server that never
  // listened would run on until its --duration.
  try {
    wait_until_listening(web);
  } catch (...) {
    discard();
    throw;
  }
}

void ServerProcess::wait_until_listening(bool web) {
  const std::regex listening("listening on 127\\.0\\.0\\.1:([0-9]+)");
  const std::regex web_viewer("web viewer on http://127\\.0\\.0\\.1:([0-9]+)/");
  bool listens = false;
  const auto listening_now = [&] {
    const std::string text = log();
    std::smatch m, w;
    if (!std::regex_search(text, m, listening) || (web && !std::regex_search(text, w, web_viewer))) return false;
    port_ = static_cast<std::uint16_t>(std::stoi(m[1]));
    if (web) web_port_ = static_cast<std::uint16_t>(std::stoi(w[1]));
    listens = true;
    return true;
  };
  wait_until([&] { return !running() || listening_now(); }, std::chrono::seconds(15), std::chrono::milliseconds(20));
  if (!listens) throw std::runtime_error("fishtank-server did not start listening; its log:\n" + log());
}

void ServerProcess::discard() {
  if (running()) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    reaped_ = true;
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

ServerProcess::~ServerProcess() { discard(); }

bool ServerProcess::running() {
  // pid -1 would make waitpid reap any child of the test.
  if (reaped_ || pid_ <= 0) return false;
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

bool ServerProcess::wait_for_log(const std::string& text, std::chrono::milliseconds timeout) const {
  return wait_until([&] { return log().find(text) != std::string::npos; }, timeout);
}

void ServerProcess::request_stop() {
  if (stop_requested_ || !running()) return;
  kill(pid_, SIGTERM);
  stop_requested_ = true;
}

int ServerProcess::terminate() {
  request_stop();
  if (!running()) return exit_status_;
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

}  // namespace fishtank::test
