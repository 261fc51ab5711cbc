#pragma once
// Boost.Thread worker pool that runs one phase of a step on every thread.
//
//   caller (thread 0) ── run(phase) ──► generation++ ──► workers 1..T-1 wake
//        │ claims chunks                                 each claims chunks
//        └──────── waits until every chunk is done ◄─────────┘
//
// Each thread owns a contiguous run of a few chunks, so on a quiet machine it
// streams through the same arrays pass after pass; a thread done with its own
// takes unstarted chunks from the back of the others' runs, so a thread the OS
// has not scheduled holds up a pass by at most the chunk it is inside. Claims
// carry the phase's generation: a late worker cannot take a later phase's chunk.
// Each item is computed by exactly one thread, the same way: results never
// depend on the thread count.
//
// While every thread steps, and there are as many threads as the process may
// use CPUs, each thread is pinned to its own CPU. Unpinned, the kernel's
// wake-up placement can put the caller and a worker on one core beside busy
// processes on the other, a balanced-looking state it keeps, in which the two
// take turns at one core. With a lower limit the threads run wherever the
// kernel puts them. Threads the caller starts while pinned inherit its CPU.

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
  // Items [begin, end) of the phase. `chunk` numbers the chunks in item order,
  // below max_chunks(), so a phase can keep one result per chunk.
  using Phase = std::function<void(std::uint32_t begin, std::uint32_t end, int chunk)>;

  WorkerPool(int threads, std::uint32_t granule);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return thread_count_; }
  // The CPUs the process could use when the pool was made, in order.
  const std::vector<int>& cpus() const { return cpus_; }
  int max_chunks() const { return thread_count_ * kChunksPerThread; }
  // Passes use at most this many threads (1..threads()); the others stay idle.
  void set_active_limit(int limit);
  int active_limit() const { return active_limit_; }
  // The threads a run() over `count` items takes now: the active limit, fewer where the items are too few to split.
  int threads_for(std::uint32_t count) const;
  // Runs phase on `count` items, in chunks claimed by the active threads.
  void run(std::uint32_t count, const Phase& phase);
  // For costly items (a strayed ball's check): split from `min_per_thread` per thread, any chunk length.
  void run_costly(std::uint32_t count, std::uint32_t min_per_thread, const Phase& phase);
  // Each thread's fraction of the items computed since the last reset_shares()
  // (or construction), one entry per thread.
  std::vector<double> shares() const;
  void reset_shares();
  // Wakes sleeping workers so they poll when a run() comes soon: a paced caller pays the wake-up
  // while it waits, not inside its batch.
  void wake();
  // For tests: called on a worker as it picks up a phase, to stall it on purpose. Set before the first run.
  void set_worker_hook(std::function<void(int thread)> hook) { worker_hook_ = std::move(hook); }

  // The run-time default: one thread per core this process may run on (its
  // CPU affinity, as taskset or a container sets it), not per core installed.
  static int hardware_threads();

 private:
  // The threads a run over `count` items takes: at least min_per_thread each, at most the active limit, one at least.
  int active_threads(std::uint32_t count, std::uint32_t min_per_thread) const;
  // Few enough that claiming is cheap, enough that a stalled thread's work is taken in small pieces.
  static constexpr int kChunksPerThread = 4;

  // A thread's unclaimed chunks [front, back) of generation `tag`: one word, so a claim is one CAS.
  struct alignas(64) Claims {
    std::atomic<std::uint64_t> word{0};
  };
  struct alignas(64) ItemCount {
    std::uint64_t items = 0;
  };

  void worker_loop(int thread);
  // Runs chunks until none is left: the thread's own from the front, then the others' from the back.
  void work(int thread, std::uint64_t generation);
  int claim(int owner, bool from_front, std::uint32_t tag);
  void run(std::uint32_t count, const Phase& phase, std::uint32_t granule, std::uint32_t min_per_thread);
  void wait_for_chunks();
  // Pins the threads one per CPU, or frees them to every CPU the process may use.
  void place_threads(bool one_per_cpu);

  int thread_count_;
  std::uint32_t granule_;
  int active_limit_;
  std::vector<boost::thread> workers_;
  std::function<void(int)> worker_hook_;
  // The current phase, written before its generation is published.
  const Phase* phase_ = nullptr;
  std::uint32_t chunk_count_ = 0;
  std::vector<std::uint32_t> chunk_start_;  // chunk c is [start[c], start[c + 1])
  std::vector<Claims> claims_;
  std::vector<ItemCount> items_done_;  // per thread, since reset_shares()
  std::vector<int> cpus_;              // thread t's CPU is cpus_[t] when pinned
  bool pins_;                          // one CPU per thread: pins while every thread steps
  bool workers_pinned_ = false;
  // Phases published so far (high bits) and the threads they use (low byte).
  std::atomic<std::uint64_t> generation_{0};
  std::atomic<std::uint64_t> wake_calls_{0};
  std::atomic<std::uint32_t> chunks_done_{0};
  std::atomic<bool> stopping_{false};
  boost::mutex mutex_;
  boost::condition_variable wake_;
};

}  // namespace fishtank
