#include "server/physics/worker_pool.h"

#include <immintrin.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "common/fp_env.h"

namespace fishtank {

namespace {
using Clock = std::chrono::steady_clock;
// How long an idle worker polls before it sleeps: long enough to bridge the
// gaps between the passes of a step, short enough that a paced server's
// workers sleep between its batches of steps.
constexpr auto kWorkerSpin = std::chrono::microseconds(1000);
// How long the caller polls for the last chunks before it yields between
// polls, so that a thread descheduled inside a chunk can get the core back.
// Yielding kept more of the caller's share of a busy machine than sleeping on
// a condition variable (technical report 5.1).
constexpr auto kCallerSpin = std::chrono::microseconds(50);
// Fewer items than this per thread cost more to hand out than to compute.
constexpr std::uint32_t kMinItemsPerThread = 1024;
// generation_ keeps the active thread count in its low bits.
constexpr int kActiveBits = 16;
constexpr std::uint64_t kActiveMask = (std::uint64_t{1} << kActiveBits) - 1;

// Claims::word: the generation's low 32 bits, then front and back, 16 bits each.
std::uint64_t claims_word(std::uint32_t tag, std::uint32_t front, std::uint32_t back) {
  return std::uint64_t{tag} << 32 | std::uint64_t{front} << 16 | back;
}

// The CPUs this process may run on. Read once, on first use: the mask is the
// calling thread's, and a pool pins its caller to one CPU while it steps.
const std::vector<int>& allowed_cpus() {
  static const std::vector<int> cpus = [] {
    cpu_set_t set;
    CPU_ZERO(&set);
    std::vector<int> found;
    if (sched_getaffinity(0, sizeof set, &set) != 0) return found;
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &set)) found.push_back(c);
    return found;
  }();
  return cpus;
}

// Restricts a thread to `cpus`; a failure leaves it where it was, which costs only speed.
void set_cpus(pthread_t thread, const std::vector<int>& cpus) {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int c : cpus) CPU_SET(c, &set);
  pthread_setaffinity_np(thread, sizeof set, &set);
}

void pause_until(const std::atomic<std::uint64_t>& value, std::uint64_t seen, Clock::time_point give_up) {
  for (int spins = 1; value.load(std::memory_order_acquire) == seen; ++spins) {
    _mm_pause();
    if (spins % 64 == 0 && Clock::now() > give_up) return;
  }
}
}  // namespace

int WorkerPool::hardware_threads() {
  const std::size_t allowed = allowed_cpus().size();
  return allowed > 0 ? static_cast<int>(allowed)
                     : static_cast<int>(std::max(1u, boost::thread::hardware_concurrency()));
}

WorkerPool::WorkerPool(int threads, std::uint32_t granule)
    : thread_count_(std::clamp(threads, 1, 1 << 10)),
      granule_(std::max(1u, granule)),
      active_limit_(thread_count_),
      chunk_start_(max_chunks() + 1),
      claims_(thread_count_),
      items_done_(thread_count_),
      cpus_(allowed_cpus()),
      pins_(thread_count_ > 1 && static_cast<int>(cpus_.size()) == thread_count_) {
  for (int t = 1; t < thread_count_; ++t) workers_.emplace_back([this, t] { worker_loop(t); });
}

WorkerPool::~WorkerPool() {
  place_threads(false);  // a caller that outlives the pool gets every CPU back
  {
    boost::lock_guard<boost::mutex> lock(mutex_);
    stopping_ = true;
    generation_.fetch_add(std::uint64_t{1} << kActiveBits);
  }
  wake_.notify_all();
  for (boost::thread& w : workers_) w.join();
}

void WorkerPool::set_active_limit(int limit) { active_limit_ = std::clamp(limit, 1, thread_count_); }

std::vector<double> WorkerPool::shares() const {
  double total = 0.0;
  for (const ItemCount& done : items_done_) total += done.items;
  std::vector<double> share(thread_count_, 0.0);
  for (int t = 0; t < thread_count_ && total > 0.0; ++t) share[t] = items_done_[t].items / total;
  return share;
}

void WorkerPool::reset_shares() {
  for (ItemCount& done : items_done_) done.items = 0;
}

int WorkerPool::claim(int owner, bool from_front, std::uint32_t tag) {
  std::atomic<std::uint64_t>& word = claims_[owner].word;
  std::uint64_t w = word.load(std::memory_order_acquire);
  for (;;) {
    const std::uint32_t front = (w >> 16) & 0xffff, back = w & 0xffff;
    if (std::uint32_t(w >> 32) != tag || front >= back) return -1;
    const std::uint64_t next = from_front ? claims_word(tag, front + 1, back) : claims_word(tag, front, back - 1);
    if (word.compare_exchange_weak(w, next, std::memory_order_acq_rel, std::memory_order_acquire))
      return static_cast<int>(from_front ? front : back - 1);
  }
}

void WorkerPool::work(int thread, std::uint64_t generation) {
  const auto tag = static_cast<std::uint32_t>(generation >> kActiveBits);
  const auto active = static_cast<int>(generation & kActiveMask);
  // Read once a chunk is held: until every chunk is done, nothing changes them.
  const auto run_chunk = [&](int c) {
    const std::uint32_t begin = chunk_start_[c], end = chunk_start_[c + 1];
    if (begin < end) (*phase_)(begin, end, c);
    items_done_[thread].items += end - begin;
    chunks_done_.fetch_add(1, std::memory_order_release);
  };
  for (int c; (c = claim(thread, true, tag)) >= 0;) run_chunk(c);
  for (int k = 1; k < active; ++k)
    for (int c; (c = claim((thread + k) % active, false, tag)) >= 0;) run_chunk(c);
}

void WorkerPool::wait_for_chunks() {
  const std::uint32_t total = chunk_count_;
  const Clock::time_point give_up = Clock::now() + kCallerSpin;
  for (int spins = 1; chunks_done_.load(std::memory_order_acquire) != total; ++spins) {
    if (spins % 64 != 0 || Clock::now() < give_up)
      _mm_pause();
    else
      boost::this_thread::yield();
  }
}

void WorkerPool::run(std::uint32_t count, const Phase& phase) { run(count, phase, granule_, kMinItemsPerThread); }

int WorkerPool::threads_for(std::uint32_t count) const { return active_threads(count, kMinItemsPerThread); }

int WorkerPool::active_threads(std::uint32_t count, std::uint32_t min_per_thread) const {
  return std::max(1, static_cast<int>(std::min<std::uint32_t>(count / min_per_thread, active_limit_)));
}

void WorkerPool::run_costly(std::uint32_t count, std::uint32_t min_per_thread, const Phase& phase) {
  run(count, phase, 1, std::max(1u, min_per_thread));
}

void WorkerPool::place_threads(bool one_per_cpu) {
  // The caller's placement is the calling thread's own, whichever pool pinned it.
  thread_local bool caller_pinned = false;
  if (!pins_) return;
  if (caller_pinned != one_per_cpu) {
    set_cpus(pthread_self(), one_per_cpu ? std::vector<int>{cpus_[0]} : cpus_);
    caller_pinned = one_per_cpu;
  }
  if (workers_pinned_ != one_per_cpu) {
    for (int t = 1; t < thread_count_; ++t)
      set_cpus(workers_[t - 1].native_handle(), one_per_cpu ? std::vector<int>{cpus_[t]} : cpus_);
    workers_pinned_ = one_per_cpu;
  }
}

void WorkerPool::run(std::uint32_t count, const Phase& phase, std::uint32_t granule, std::uint32_t min_per_thread) {
  place_threads(active_limit_ == thread_count_);
  const int active = active_threads(count, min_per_thread);
  if (active <= 1) {
    if (count > 0) phase(0, count, 0);
    items_done_[0].items += count;
    return;
  }
  const std::uint32_t granules = (count + granule - 1) / granule;
  chunk_count_ = std::min<std::uint32_t>(active * kChunksPerThread, granules);
  chunk_start_[0] = 0;
  for (std::uint32_t c = 1; c < chunk_count_; ++c) {
    // The nearest multiple of the granule: rounding down would give the last chunk up to a granule more.
    const double start = std::floor(double(count) * c / chunk_count_ / granule + 0.5) * granule;
    chunk_start_[c] = std::max(chunk_start_[c - 1], static_cast<std::uint32_t>(std::min<double>(count, start)));
  }
  chunk_start_[chunk_count_] = count;

  const std::uint64_t generation =
      ((generation_.load(std::memory_order_relaxed) >> kActiveBits) + 1) << kActiveBits | std::uint64_t(active);
  const auto tag = static_cast<std::uint32_t>(generation >> kActiveBits);
  for (int t = 0; t < thread_count_; ++t) {
    const std::uint32_t front = t < active ? chunk_count_ * t / active : 0;
    const std::uint32_t back = t < active ? chunk_count_ * (t + 1) / active : 0;
    claims_[t].word.store(claims_word(tag, front, back), std::memory_order_relaxed);
  }
  phase_ = &phase;
  chunks_done_.store(0, std::memory_order_relaxed);
  {
    // Taking the lock orders the publish against a worker that is about to sleep.
    boost::lock_guard<boost::mutex> lock(mutex_);
    generation_.store(generation, std::memory_order_release);
  }
  wake_.notify_all();
  work(0, generation);
  wait_for_chunks();
}

void WorkerPool::wake() {
  if (active_limit_ <= 1) return;  // no pass will hand a worker anything
  {
    boost::lock_guard<boost::mutex> lock(mutex_);
    wake_calls_.fetch_add(1, std::memory_order_relaxed);
  }
  wake_.notify_all();
}

void WorkerPool::worker_loop(int thread) {
  enable_flush_denormals_to_zero();
  std::uint64_t seen = 0;
  for (;;) {
    pause_until(generation_, seen, Clock::now() + kWorkerSpin);
    if (generation_.load(std::memory_order_acquire) == seen) {
      boost::unique_lock<boost::mutex> lock(mutex_);
      const std::uint64_t wake_calls = wake_calls_.load(std::memory_order_relaxed);
      wake_.wait(lock, [&] {
        return generation_.load(std::memory_order_acquire) != seen ||
               wake_calls_.load(std::memory_order_relaxed) != wake_calls;
      });
      if (generation_.load(std::memory_order_acquire) == seen) continue;  // woken ahead of work: poll again
    }
    seen = generation_.load(std::memory_order_acquire);
    if (stopping_.load()) return;
    if (thread >= static_cast<int>(seen & kActiveMask)) continue;
    if (worker_hook_) worker_hook_(thread);
    work(thread, seen);
  }
}

}  // namespace fishtank
