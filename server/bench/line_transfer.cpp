#include "server/bench/line_transfer.h"

#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <thread>

namespace fishtank {

namespace {

// The flag alone on its line, and on the line beside it, which some cores
// fetch in pairs: it is the line that travels. Odd values go from a to b,
// even ones back; kOff calls the trips off.
struct alignas(128) Flag {
  std::atomic<int> value{0};
};
constexpr int kOff = -1;

bool pin_to(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}

// Pins the calling thread and waits for the other one; false when either
// could not be pinned.
bool start_together(int cpu, Flag& flag, Flag& ready) {
  if (!pin_to(cpu)) flag.value.store(kOff, std::memory_order_release);
  ready.value.fetch_add(1, std::memory_order_acq_rel);
  while (ready.value.load(std::memory_order_acquire) < 2) {
  }
  return flag.value.load(std::memory_order_acquire) != kOff;
}

bool wait_for(const Flag& flag, int expected) {
  int seen;
  while ((seen = flag.value.load(std::memory_order_acquire)) != expected)
    if (seen == kOff) return false;
  return true;
}

// Side a sends the odd values and times the trips; side b answers. Each
// loop touches the flag's line alone (everything else is in registers), so
// that the time is the line's, not that of other lines the threads share.
double send(int cpu, Flag& flag, Flag& ready, int round_trips) {
  if (!start_together(cpu, flag, ready)) return 0.0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < round_trips; ++i) {
    flag.value.store(2 * i + 1, std::memory_order_release);
    if (!wait_for(flag, 2 * i + 2)) return 0.0;
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void answer(int cpu, Flag& flag, Flag& ready, int round_trips) {
  if (!start_together(cpu, flag, ready)) return;
  for (int i = 0; i < round_trips; ++i) {
    if (!wait_for(flag, 2 * i + 1)) return;
    flag.value.store(2 * i + 2, std::memory_order_release);
  }
}

}  // namespace

std::optional<LineTransfer> time_line_transfer(int round_trips) {
  cpu_set_t allowed;
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return std::nullopt;
  std::vector<int> cpus;
  for (int cpu = 0; cpu < CPU_SETSIZE && cpus.size() < 2; ++cpu)
    if (CPU_ISSET(cpu, &allowed)) cpus.push_back(cpu);
  return time_line_transfer(cpus, round_trips);
}

std::optional<LineTransfer> time_line_transfer(const std::vector<int>& cpus, int round_trips) {
  if (cpus.size() < 2 || round_trips < 1) return std::nullopt;
  LineTransfer t;
  t.cpu_a = cpus[0], t.cpu_b = cpus[1];

  Flag flag, ready;  // ready counts the threads pinned
  double seconds = 0.0;
  std::thread b(answer, t.cpu_b, std::ref(flag), std::ref(ready), round_trips);
  std::thread a(
      [&seconds, cpu = t.cpu_a, &flag, &ready, round_trips] { seconds = send(cpu, flag, ready, round_trips); });
  a.join();
  b.join();
  if (!(seconds > 0.0)) return std::nullopt;  // a thread could not be pinned
  t.ns = seconds / round_trips / 2.0 * 1e9;
  return t;
}

}  // namespace fishtank
