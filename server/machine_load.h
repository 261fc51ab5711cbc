#pragma once
// How many of the machine's cores other work keeps busy, from the kernel's
// counters: the CPU time /proc/stat counts as busy on every CPU (the
// hypervisor's steal included) less this process's own.
//
// Where the kernel shares CPU time between sessions (autogroup, Debian's
// default), work in other sessions leaves this process the same share however
// many threads it runs, and a worker preempted inside a chunk holds up its
// pass: one thread steps faster than all. Work in this process's own session
// is shared per thread, so more threads do win a larger share; it is read from
// /proc/<pid>/stat while others are busy. Niced work is left out: it yields to
// the simulation.

#include <optional>
#include <string_view>
#include <unordered_map>

namespace fishtank {

class MachineLoad {
 public:
  // Seconds between readings, and the weight a new reading gets: the figure
  // follows a change of load within a few readings.
  static constexpr double kInterval = 0.05;
  static constexpr double kWeight = 0.5;
  // Below this many cores of other work, its session is not looked up; when
  // it is, at each reading until measured, then every kSessionInterval (a file
  // read per process).
  static constexpr double kLookUpSessions = 0.5;
  static constexpr double kSessionInterval = 0.25;

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

  // A process's session and CPU seconds, from the text of its /proc/<pid>/stat.
  struct Process {
    int session = 0;
    double cpu = 0.0;
  };
  static std::optional<Process> parse_pid_stat(std::string_view text, double ticks_per_second);

  // Whether the kernel shares CPU time between sessions (/proc/sys/kernel/sched_autogroup_enabled).
  explicit MachineLoad(bool sessions_share = autogroup_enabled());
  static bool autogroup_enabled();

  // Takes a reading if kInterval has passed since the last one (`now` in seconds).
  void update(double now);
  // A reading of the machine's counters.
  void add_reading(const Counters& counters, double now);
  // A look-up: the cores this session's other processes kept busy since the last one.
  void add_session_reading(double cores);
  bool measured() const { return measured_; }
  // The others' cores, smoothed over the last few readings; 0 until measured.
  double others() const { return others_; }
  // Of those, the cores of work in other sessions: what crowds this process.
  double crowding() const;
  int cpus() const { return last_ ? last_->cpus : 0; }
  // Whether `threads` threads each find a core that work in other sessions leaves (nearly) free.
  bool room_for(int threads) const;
  // Whether other work that the kernel shares the cores with per thread (this
  // session's, or any where sessions do not share) keeps half a core or more
  // busy: more threads then win a larger share.
  bool shared_per_thread() const;

 private:
  // CPU seconds this session's other processes used since the last call (those seen both times).
  std::optional<double> session_cpu_since_last();
  void look_up_session(double now);

  bool sessions_share_;
  std::optional<Counters> last_;
  double last_at_ = 0.0;
  double others_ = 0.0, session_others_ = 0.0;
  bool measured_ = false, session_measured_ = false;
  bool unreadable_ = false;
  std::unordered_map<int, double> session_cpu_;  // by pid, at the last look-up
  std::optional<double> looked_up_at_;           // when, while look-ups follow one another
};

}  // namespace fishtank
