#pragma once
// Boost.Thread worker pool that runs one phase of a step on every thread.
//
//   caller (thread 0) ── run(phase) ──► generation++ ──► workers 1..T-1 wake
//        │ does chunk 0                                   each does chunk t
//        └──────── waits until `pending` reaches 0 ◄─────────┘
//
// Work is split into T contiguous chunks, so each thread streams through its
// own part of the arrays. Chunks start at multiples of a granule, so every
// pass over the same count puts each granule-sized block of items on one
// thread, whatever the number of threads (the SIMD kernels keep per-block
// data from one pass to the next).
//
// The split follows the threads' speeds. Cores of a virtual machine are not
// equal: on this project's 2-core machine one of them ran 30 % slower than
// the other for minutes at a time (a neighbour on the host), and with equal
// chunks the fast thread then waits for the slow one at the end of every
// pass. run_and_balance() times each chunk and moves every later split
// towards chunks that take equal time (smoothed, and only for a clear
// imbalance, so that noise does not shuffle blocks between cores: a block
// that changes thread costs its cache lines a trip between the cores). A
// phase lasts tens of microseconds in benchmark mode, so workers spin briefly
// before sleeping on a condition variable: a wake-up from spinning costs well
// under a microsecond, one from sleep several. With one thread, run() is a
// plain call with no synchronisation at all, and so is a phase too small to
// be worth splitting (under ~1000 items per thread). Results never depend on
// the split, so neither on timing: each item is computed by exactly one
// thread, the same way.

#include <atomic>
#include <boost/thread/condition_variable.hpp>
#include <boost/thread/mutex.hpp>
#include <boost/thread/thread.hpp>
#include <cstdint>
#include <functional>
#include <vector>

namespace fishtank {

class WorkerPool {
 public:
  // Chunk [begin, end) of `count` items, on thread `thread`.
  using Phase = std::function<void(std::uint32_t begin, std::uint32_t end, int thread)>;

  WorkerPool(int threads, std::uint32_t granule);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return thread_count_; }
  // Passes use at most this many threads (1..threads()); the others stay idle.
  void set_active_limit(int limit);
  int active_limit() const { return active_limit_; }
  // Runs phase on `count` items, one chunk per thread, split by the speeds
  // measured so far (equal chunks until a run has measured them).
  void run(std::uint32_t count, const Phase& phase);
  // The same, timing each thread's chunk to adapt later splits: for the pass
  // that takes most of the time, whose chunks' speeds the split should match.
  void run_and_balance(std::uint32_t count, const Phase& phase);
  // For items that each cost as much as hundreds of balls' steps (a far
  // ball's check): splits from `min_per_thread` items per thread, in chunks
  // of any length, by the same speeds.
  void run_costly(std::uint32_t count, std::uint32_t min_per_thread, const Phase& phase);
  // Each thread's fraction of the items in a run on `active` threads.
  std::vector<double> shares(int active) const;
  // Wakes sleeping workers now so that they are polling, not asleep, when a
  // run() comes within the next millisecond: a paced caller pays the wake-up
  // while it waits for its next batch instead of inside the batch.
  void wake();

  // The run-time default: one thread per available core.
  static int hardware_threads();

 private:
  // One chunk's duration, on its own cache line: each thread writes its own.
  struct alignas(64) ChunkTime {
    double seconds = 0.0;
  };

  void worker_loop(int thread);
  void run_chunk(int thread);
  // What a run's items cost: chunks start at multiples of `granule`, and a
  // run is split only with at least `min_per_thread` items per thread.
  struct Grain {
    std::uint32_t granule, min_per_thread;
  };
  void run(std::uint32_t count, const Phase& phase, Grain grain, bool timed);
  void split(std::uint32_t count, std::uint32_t granule);
  void balance();

  int thread_count_;
  std::uint32_t granule_;
  int active_limit_;
  std::vector<boost::thread> workers_;
  const Phase* phase_ = nullptr;
  int active_ = 1;  // threads given a chunk in the current phase
  bool timed_ = false;
  std::vector<std::uint32_t> chunk_start_;  // the current phase's chunks: [start[t], start[t + 1])
  std::vector<ChunkTime> chunk_time_;
  std::vector<double> speed_;  // per thread, relative: the split gives each a share in proportion
  std::atomic<std::uint64_t> generation_{0};
  std::atomic<std::uint64_t> wake_calls_{0};
  std::atomic<int> pending_{0};
  std::atomic<bool> stopping_{false};
  boost::mutex mutex_;
  boost::condition_variable wake_;
};

}  // namespace fishtank
