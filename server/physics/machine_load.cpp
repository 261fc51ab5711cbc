#include "server/physics/machine_load.h"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <ctime>
#include <fstream>
#include <iterator>
#include <string>

namespace fishtank {

namespace {
// The first numbers of a /proc/stat "cpu" line, in its order (proc(5)); guest time is already in user and nice.
enum Field { kUser, kNice, kSystem, kIdle, kIowait, kIrq, kSoftirq, kSteal, kFields };

bool starts_with(std::string_view text, std::string_view prefix) { return text.substr(0, prefix.size()) == prefix; }
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
      line.remove_prefix(std::min(line.find_first_not_of(' '), line.size()));
      unsigned long long ticks = 0;
      const auto [next, error] = std::from_chars(line.data(), line.data() + line.size(), ticks);
      if (error != std::errc()) {
        if (f <= kIdle) return std::nullopt;  // kernels before 2.6.11 give fewer fields: the rest stay 0
        break;
      }
      field[f] = static_cast<double>(ticks) / ticks_per_second;
      line.remove_prefix(static_cast<std::size_t>(next - line.data()));
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
  std::ifstream file("/proc/stat");
  const std::string text{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  const long ticks = sysconf(_SC_CLK_TCK);
  std::optional<Counters> counters = parse_proc_stat(text, ticks > 0 ? double(ticks) : 100.0);
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

void MachineLoad::update(double now) {
  if (unreadable_ || (last_ && now - last_at_ < kInterval)) return;
  if (const std::optional<Counters> counters = read())
    add_reading(*counters, now);
  else
    unreadable_ = true;  // not Linux, or no /proc: every thread keeps its room
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

bool MachineLoad::room_for(int threads) const {
  if (!measured_) return true;
  const int wanted = std::min(threads, cpus());
  return cpus() - others_ >= wanted - 0.5;
}

}  // namespace fishtank
