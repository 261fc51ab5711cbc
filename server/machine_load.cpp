#include "server/machine_load.h"

#include <dirent.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <ctime>
#include <string>

namespace fishtank {

namespace {
// The first numbers of a /proc/stat "cpu" line, in its order (proc(5)); guest time is already in user and nice.
enum Field { kUser, kNice, kSystem, kIdle, kIowait, kIrq, kSoftirq, kSteal, kFields };

bool starts_with(std::string_view text, std::string_view prefix) { return text.substr(0, prefix.size()) == prefix; }

// A small /proc file, or "" where it cannot be opened (no descriptor left, the process gone). Plain
// POSIX reads: /proc files are generated as they are read, and this runs in the physics thread.
std::string read_file(const std::string& path) {
  std::string text;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return text;
  char buffer[4096];
  for (ssize_t got; (got = ::read(fd, buffer, sizeof buffer)) > 0;) text.append(buffer, static_cast<std::size_t>(got));
  ::close(fd);
  return text;
}

double ticks_per_second() {
  const long ticks = sysconf(_SC_CLK_TCK);
  return ticks > 0 ? double(ticks) : 100.0;
}

// The next space-separated number of `text`, consumed.
template <class Number = unsigned long long>
std::optional<Number> next_number(std::string_view& text) {
  text.remove_prefix(std::min(text.find_first_not_of(' '), text.size()));
  Number value = 0;
  const auto [next, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc()) return std::nullopt;
  text.remove_prefix(static_cast<std::size_t>(next - text.data()));
  return value;
}
}  // namespace

std::optional<MachineLoad::Counters> MachineLoad::parse_proc_stat(std::string_view text, double ticks_per_second) {
  std::optional<Counters> counters;
  int cpus = 0;
  while (!text.empty()) {
    const std::size_t end = std::min(text.find('\n'), text.size());
    std::string_view line = text.substr(0, end);
    text.remove_prefix(std::min(end + 1, text.size()));
    if (!starts_with(line, "cpu")) continue;
    if (line.size() > 3 && line[3] != ' ') {  // "cpuN": one CPU
      ++cpus;
      continue;
    }
    double field[kFields] = {};
    line.remove_prefix(3);
    for (int f = 0; f < kFields; ++f) {
      const std::optional<unsigned long long> ticks = next_number(line);
      if (!ticks) {
        if (f <= kIdle) return std::nullopt;  // kernels before 2.6.11 give fewer fields: the rest stay 0
        break;
      }
      field[f] = static_cast<double>(*ticks) / ticks_per_second;
    }
    Counters c;
    c.busy = field[kUser] + field[kSystem] + field[kIrq] + field[kSoftirq] + field[kSteal];
    c.total = c.busy + field[kNice] + field[kIdle] + field[kIowait];
    counters = c;
  }
  if (counters) counters->cpus = std::max(cpus, 1);
  return counters;
}

std::optional<MachineLoad::Counters> MachineLoad::read() {
  std::optional<Counters> counters = parse_proc_stat(read_file("/proc/stat"), ticks_per_second());
  timespec own{};
  if (!counters || clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &own) != 0) return std::nullopt;
  counters->own = double(own.tv_sec) + 1e-9 * double(own.tv_nsec);
  return counters;
}

double MachineLoad::others_between(const Counters& earlier, const Counters& later) {
  const double total = later.total - earlier.total;
  if (!(total > 0.0)) return 0.0;
  const double others = (later.busy - earlier.busy) - (later.own - earlier.own);
  return std::clamp(others / total, 0.0, 1.0) * later.cpus;
}

std::optional<MachineLoad::Process> MachineLoad::parse_pid_stat(std::string_view text, double ticks_per_second) {
  // "pid (comm) state ppid pgrp session ... utime stime ...": comm may hold spaces and parentheses.
  const std::size_t comm_end = text.rfind(')');
  if (comm_end == std::string_view::npos) return std::nullopt;
  text.remove_prefix(comm_end + 1);
  text.remove_prefix(std::min(text.find_first_not_of(' '), text.size()));
  text.remove_prefix(std::min(text.find(' '), text.size()));  // the state letter
  long long field[12] = {};  // ppid pgrp session tty_nr tpgid (-1 without a terminal) ... utime stime
  for (long long& f : field) {
    const std::optional<long long> value = next_number<long long>(text);
    if (!value) return std::nullopt;
    f = *value;
  }
  return Process{static_cast<int>(field[2]), static_cast<double>(field[10] + field[11]) / ticks_per_second};
}

MachineLoad::MachineLoad(bool sessions_share) : sessions_share_(sessions_share) {}

bool MachineLoad::autogroup_enabled() {
  return starts_with(read_file("/proc/sys/kernel/sched_autogroup_enabled"), "1");
}

std::optional<double> MachineLoad::session_cpu_since_last() {
  const int self = static_cast<int>(getpid()), session = static_cast<int>(getsid(0));
  const double ticks = ticks_per_second();
  std::unordered_map<int, double> now;
  double used = 0.0;
  DIR* const proc = opendir("/proc");
  if (!proc) {  // no descriptor left: the next look-up starts afresh
    session_cpu_.clear();
    looked_up_at_.reset();
    return std::nullopt;
  }
  while (const dirent* entry = readdir(proc)) {
    const std::string_view name = entry->d_name;
    int pid = 0;
    const auto [end, bad] = std::from_chars(name.data(), name.data() + name.size(), pid);
    if (bad != std::errc() || end != name.data() + name.size() || pid == self) continue;
    const std::optional<Process> p = parse_pid_stat(read_file("/proc/" + std::string(name) + "/stat"), ticks);
    if (!p || p->session != session) continue;
    now[pid] = p->cpu;
    if (const auto before = session_cpu_.find(pid); before != session_cpu_.end())
      used += std::max(0.0, p->cpu - before->second);
  }
  closedir(proc);
  session_cpu_ = std::move(now);
  return used;
}

void MachineLoad::look_up_session(double now) {
  const std::optional<double> since = looked_up_at_;
  looked_up_at_ = now;
  const std::optional<double> used = session_cpu_since_last();
  if (used && since && now > *since) add_session_reading(*used / (now - *since));
}

void MachineLoad::update(double now) {
  if (unreadable_ || (last_ && now - last_at_ < kInterval)) return;
  const std::optional<Counters> counters = read();
  if (!counters) {
    unreadable_ = true;  // not Linux, or no /proc: every thread keeps its room
    return;
  }
  add_reading(*counters, now);
  if (!sessions_share_ || others_ < kLookUpSessions) {
    looked_up_at_.reset();
    session_others_ = 0.0, session_measured_ = false;
  } else if (!session_measured_ || !looked_up_at_ ||
             now - *looked_up_at_ >= kSessionInterval) {  // at once until measured
    look_up_session(now);
  }
}

void MachineLoad::add_reading(const Counters& counters, double now) {
  if (last_) {
    const double others = others_between(*last_, counters);
    others_ = measured_ ? others_ + kWeight * (others - others_) : others;
    measured_ = true;
  }
  last_ = counters;
  last_at_ = now;
}

void MachineLoad::add_session_reading(double cores) {
  session_others_ = session_measured_ ? session_others_ + kWeight * (cores - session_others_) : cores;
  session_measured_ = true;
}

double MachineLoad::crowding() const {
  if (!sessions_share_) return 0.0;  // every thread is shared alike: more threads, more share
  return std::max(0.0, others_ - session_others_);
}

bool MachineLoad::shared_per_thread() const {
  if (!measured_) return false;
  return (sessions_share_ ? (session_measured_ ? session_others_ : 0.0) : others_) >= kLookUpSessions;
}

bool MachineLoad::room_for(int threads) const {
  if (!measured_) return true;
  const int wanted = std::min(threads, cpus());
  return cpus() - crowding() >= wanted - 0.5;
}

}  // namespace fishtank
