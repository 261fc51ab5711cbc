// MachineLoad reads how many cores other work keeps busy from /proc/stat's
// counters less this process's CPU time, and says whether every thread would
// find a core of its own.

#include "server/machine_load.h"

#include <catch2/catch.hpp>
#include <string>

using fishtank::MachineLoad;

namespace {

// /proc/stat's first lines for two CPUs: the "cpu" totals (user nice system
// idle iowait irq softirq steal guest guest_nice), then each CPU.
std::string proc_stat(long user, long nice, long system, long idle, long steal) {
  const std::string totals = std::to_string(user) + " " + std::to_string(nice) + " " + std::to_string(system) + " " +
                             std::to_string(idle) + " 0 0 0 " + std::to_string(steal) + " 0 0\n";
  return "cpu  " + totals + "cpu0 " + totals + "cpu1 " + totals + "intr 1 2 3\nctxt 99\n";
}

MachineLoad::Counters counters(long user, long nice, long system, long idle, long steal, double own) {
  auto c = MachineLoad::parse_proc_stat(proc_stat(user, nice, system, idle, steal), 100.0);
  REQUIRE(c);
  c->own = own;
  return *c;
}

}  // namespace

TEST_CASE("/proc/stat's totals are read as busy and total CPU seconds, niced work counted as free",
          "[server][threads]") {
  const auto c = MachineLoad::parse_proc_stat(proc_stat(300, 50, 100, 500, 20), 100.0);
  REQUIRE(c);
  CHECK(c->busy == Approx(4.2));  // user + system + steal
  CHECK(c->total == Approx(9.7));
  CHECK(c->cpus == 2);
  CHECK_FALSE(MachineLoad::parse_proc_stat("intr 1 2\n", 100.0));
  CHECK_FALSE(MachineLoad::parse_proc_stat("cpu  12 x\n", 100.0));
}

TEST_CASE("the others' cores are the machine's busy time less this process's", "[server][threads]") {
  // 0.2 s on two CPUs (40 ticks): 30 ticks busy, of which this process used 0.1 s.
  const auto a = counters(1000, 0, 0, 1000, 0, 5.0);
  const auto b = counters(1030, 0, 0, 1010, 0, 5.1);
  CHECK(MachineLoad::others_between(a, b) == Approx(1.0));  // (0.3 - 0.1) / 0.4 of 2 CPUs
  // The hypervisor's steal counts as others'; this process's own time never makes them negative.
  CHECK(MachineLoad::others_between(a, counters(1000, 0, 0, 1020, 20, 5.0)) == Approx(1.0));
  CHECK(MachineLoad::others_between(a, counters(1010, 0, 0, 1030, 0, 6.0)) == 0.0);
  CHECK(MachineLoad::others_between(a, a) == 0.0);
}

TEST_CASE("every thread has room until work in other sessions takes more than half a core of what they need",
          "[server][threads]") {
  MachineLoad load(true);
  CHECK(load.room_for(2));  // nothing measured yet
  double now = 0.0, own = 0.0;
  long busy = 0, idle = 0;
  // Each reading 0.1 s apart on 2 CPUs (20 ticks), `others` of them busy with other work.
  const auto read = [&](long others) {
    busy += others, idle += 20 - others, now += 0.1;
    load.add_reading(counters(busy, 0, 0, idle, 0, own), now);
  };
  read(0);
  read(0);
  REQUIRE(load.measured());
  CHECK(load.room_for(2));
  read(20);  // both cores taken by others: after one reading the smoothed figure is 1 core
  CHECK(load.others() == Approx(1.0));
  CHECK_FALSE(load.room_for(2));
  CHECK(load.room_for(1));  // one core is left to one thread
  read(20);
  read(20);
  CHECK_FALSE(load.room_for(1));
  // Back to idle: every thread has room again within three readings.
  read(0);
  read(0);
  read(0);
  CHECK(load.room_for(2));
}

TEST_CASE("a process's session and CPU time are read from its /proc/<pid>/stat, whatever its name",
          "[server][threads]") {
  const auto p = MachineLoad::parse_pid_stat(
      "1234 (a (b) c) R 1 1234 1200 0 -1 4194304 100 0 0 0 250 50 0 0 20 0 1 0 99 1000 10\n", 100.0);
  REQUIRE(p);
  CHECK(p->session == 1200);
  CHECK(p->cpu == Approx(3.0));  // (utime 250 + stime 50) / 100
  CHECK_FALSE(MachineLoad::parse_pid_stat("1234 (cut short) R 1 2", 100.0));
  CHECK_FALSE(MachineLoad::parse_pid_stat("no name here", 100.0));
}

TEST_CASE("work in this process's own session, or on a kernel that shares time per thread, is shared per thread",
          "[server][threads]") {
  // Both cores busy with others for a second (20 ticks per 0.1 s reading on 2 CPUs).
  const auto run = [](MachineLoad& load, double session_cores) {
    long busy = 0, idle = 0;
    for (int r = 1; r <= 10; ++r) {
      busy += 20;
      load.add_reading(counters(busy, 0, 0, idle, 0, 0.0), 0.1 * r);
      if (r % 3 == 0) load.add_session_reading(session_cores);  // looked up less often
    }
  };
  MachineLoad same_session(true), other_sessions(true), per_thread(false);
  run(same_session, 2.0);
  run(other_sessions, 0.0);
  run(per_thread, 0.0);
  CHECK(same_session.others() == Approx(2.0).margin(0.01));
  CHECK(same_session.crowding() == Approx(0.0).margin(0.01));
  CHECK(same_session.room_for(2));
  CHECK(same_session.shared_per_thread());
  CHECK(other_sessions.crowding() == Approx(2.0).margin(0.01));
  CHECK_FALSE(other_sessions.room_for(2));
  CHECK_FALSE(other_sessions.shared_per_thread());
  CHECK(per_thread.room_for(2));
  CHECK(per_thread.shared_per_thread());
}

TEST_CASE("this machine's counters can be read", "[server][threads]") {
  const auto c = MachineLoad::read();
  if (!c) {
    WARN("SKIPPED: /proc/stat cannot be read here");
    return;
  }
  CHECK(c->cpus >= 1);
  CHECK(c->total > 0.0);
  CHECK(c->busy <= c->total);
  CHECK(c->own > 0.0);
}
