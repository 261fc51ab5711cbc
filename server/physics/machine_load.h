#pragma once
// How many of the machine's cores other work keeps busy, from the kernel's
// counters: the CPU time /proc/stat counts as busy on every CPU (the
// hypervisor's steal included) less this process's own.
//
// A pass waits for its slowest thread, so when other work leaves no core free
// for each thread, stepping on one is faster than on all: the kernel gives a
// process in its own session the same share whatever its thread count
// (autogroup), and a worker preempted inside a chunk holds up the pass for a
// time slice. Niced work is left out: it yields to the simulation.

#include <optional>
#include <string_view>

namespace fishtank {

class MachineLoad {
 public:
  // Seconds between readings, and the weight a new reading gets: the figure
  // follows a change of load within a few readings.
  static constexpr double kInterval = 0.05;
  static constexpr double kWeight = 0.5;

  // Cumulative CPU seconds: the machine's busy (niced work left out) and total
  // over all its CPUs, and this process's own.
  struct Counters {
    double busy = 0.0, total = 0.0, own = 0.0;
    int cpus = 0;  // the CPUs /proc/stat lists
  };
  // The "cpu" totals and CPU count of /proc/stat's text, at `ticks_per_second`.
  static std::optional<Counters> parse_proc_stat(std::string_view text, double ticks_per_second);
  // Now, or nothing where /proc/stat cannot be read.
  static std::optional<Counters> read();
  // Cores the others kept busy between two readings: their share of the CPU time times the CPUs.
  static double others_between(const Counters& earlier, const Counters& later);

  // Takes a reading if kInterval has passed since the last one (`now` in seconds).
  void update(double now);
  void add_reading(const Counters& counters, double now);
  bool measured() const { return measured_; }
  // The others' cores, smoothed over the last few readings; 0 until measured.
  double others() const { return others_; }
  int cpus() const { return last_ ? last_->cpus : 0; }
  // Whether `threads` threads each find a core the others leave (nearly) free.
  bool room_for(int threads) const;

 private:
  std::optional<Counters> last_;
  double last_at_ = 0.0;
  double others_ = 0.0;
  bool measured_ = false;
  bool unreadable_ = false;
};

}  // namespace fishtank
