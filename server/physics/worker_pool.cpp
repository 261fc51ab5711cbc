#include "server/physics/worker_pool.h"

#include <immintrin.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "common/fp_env.h"

namespace fishtank {

namespace {
// How long an idle worker polls before it sleeps. Waking a sleeping thread
// costs tens to hundreds of microseconds on a virtual machine, paid on every
// pass if workers sleep between them: measured on the paced server with 6000
// balls, 45 % load with ~10 us of polling against 23 % with 1 ms. One
// millisecond bridges every gap inside a batch of steps, while the workers of
// a paced server still sleep through the longer gaps between batches.
constexpr auto kSpinTime = std::chrono::microseconds(1000);
// The main thread's wait for the last chunk: this many polls, then yields.
constexpr int kSpinIterations = 2000;
// Fewer items than this per thread cost more to hand out than to compute.
constexpr std::uint32_t kMinItemsPerThread = 1024;
// A timed run moves the split only when its slowest chunk took this much
// longer than the chunks' mean: below it, timing noise would move blocks
// between the cores back and forth.
constexpr double kImbalanceToAct = 0.03;
// ... and then this fraction of the way towards the split that would have
// balanced it, so that one slow run (a thread preempted) moves it little.
constexpr double kBalanceRate = 0.25;
// No thread's speed is taken as less than this fraction of the mean, so that
// each keeps a chunk to be measured by.
constexpr double kMinRelativeSpeed = 0.25;
}  // namespace

int WorkerPool::hardware_threads() { return std::max(1u, boost::thread::hardware_concurrency()); }

WorkerPool::WorkerPool(int threads, std::uint32_t granule)
    : thread_count_(std::max(1, threads)),
      granule_(std::max(1u, granule)),
      active_limit_(thread_count_),
      chunk_start_(thread_count_ + 1),
      chunk_time_(thread_count_),
      speed_(thread_count_, 1.0) {
  for (int t = 1; t < thread_count_; ++t) workers_.emplace_back([this, t] { worker_loop(t); });
}

WorkerPool::~WorkerPool() {
  {
    boost::lock_guard<boost::mutex> lock(mutex_);
    stopping_ = true;
    generation_.fetch_add(1);
  }
  wake_.notify_all();
  for (boost::thread& w : workers_) w.join();
}

void WorkerPool::set_active_limit(int limit) { active_limit_ = std::clamp(limit, 1, thread_count_); }

std::vector<double> WorkerPool::shares(int active) const {
  active = std::clamp(active, 1, thread_count_);
  const double total = std::accumulate(speed_.begin(), speed_.begin() + active, 0.0);
  std::vector<double> share(active);
  for (int t = 0; t < active; ++t) share[t] = speed_[t] / total;
  return share;
}

void WorkerPool::split(std::uint32_t count, std::uint32_t granule) {
  const double total = std::accumulate(speed_.begin(), speed_.begin() + active_, 0.0);
  double before = 0.0;
  chunk_start_[0] = 0;
  for (int t = 1; t < active_; ++t) {
    before += speed_[t - 1];
    // The nearest multiple of the granule: rounding down would hand the last thread up to a granule more.
    const double start = std::floor(count * (before / total) / granule + 0.5) * granule;
    chunk_start_[t] = std::max(chunk_start_[t - 1], static_cast<std::uint32_t>(std::min<double>(count, start)));
  }
  chunk_start_[active_] = count;
}

void WorkerPool::run_chunk(int thread) {
  if (thread >= active_) return;
  const std::uint32_t begin = chunk_start_[thread], end = chunk_start_[thread + 1];
  if (begin >= end) return;
  if (!timed_) {
    (*phase_)(begin, end, thread);
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  (*phase_)(begin, end, thread);
  chunk_time_[thread].seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void WorkerPool::balance() {
  double sum = 0.0, slowest = 0.0;
  for (int t = 0; t < active_; ++t) {
    if (chunk_start_[t] == chunk_start_[t + 1] || !(chunk_time_[t].seconds > 0.0)) return;  // nothing to go by
    sum += chunk_time_[t].seconds;
    slowest = std::max(slowest, chunk_time_[t].seconds);
  }
  if (slowest <= (1.0 + kImbalanceToAct) * sum / active_) return;
  // Items per second measured, scaled to the current speeds' total.
  double measured_total = 0.0;
  const double speed_total = std::accumulate(speed_.begin(), speed_.begin() + active_, 0.0);
  for (int t = 0; t < active_; ++t) measured_total += (chunk_start_[t + 1] - chunk_start_[t]) / chunk_time_[t].seconds;
  for (int t = 0; t < active_; ++t) {
    const double measured = (chunk_start_[t + 1] - chunk_start_[t]) / chunk_time_[t].seconds;
    const double target = measured * speed_total / measured_total;
    speed_[t] = std::max(speed_[t] + kBalanceRate * (target - speed_[t]), kMinRelativeSpeed * speed_total / active_);
  }
}

void WorkerPool::run(std::uint32_t count, const Phase& phase) {
  run(count, phase, {granule_, kMinItemsPerThread}, false);
}

void WorkerPool::run_and_balance(std::uint32_t count, const Phase& phase) {
  run(count, phase, {granule_, kMinItemsPerThread}, true);
}

void WorkerPool::run_costly(std::uint32_t count, std::uint32_t min_per_thread, const Phase& phase) {
  run(count, phase, {1, std::max(1u, min_per_thread)}, false);
}

void WorkerPool::run(std::uint32_t count, const Phase& phase, Grain grain, bool timed) {
  const int useful = static_cast<int>(std::min<std::uint32_t>(count / grain.min_per_thread, active_limit_));
  if (useful <= 1) {
    if (count > 0) phase(0, count, 0);
    return;
  }
  phase_ = &phase;
  active_ = useful;
  timed_ = timed;
  split(count, grain.granule);
  pending_.store(thread_count_ - 1, std::memory_order_relaxed);
  {
    // Taking the lock orders the publish against a worker that is about to sleep.
    boost::lock_guard<boost::mutex> lock(mutex_);
    generation_.fetch_add(1, std::memory_order_release);
  }
  wake_.notify_all();
  run_chunk(0);
  // Yield once the other threads are late, so an oversubscribed machine still progresses.
  for (int spins = 0; pending_.load(std::memory_order_acquire) != 0; ++spins) {
    if (spins < kSpinIterations)
      _mm_pause();
    else
      boost::this_thread::yield();
  }
  if (timed) balance();
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
    const auto give_up = std::chrono::steady_clock::now() + kSpinTime;
    for (int spins = 1; generation_.load(std::memory_order_acquire) == seen; ++spins) {
      _mm_pause();
      if (spins % 64 == 0 && std::chrono::steady_clock::now() > give_up) break;
    }
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
    run_chunk(thread);
    pending_.fetch_sub(1, std::memory_order_release);
  }
}

}  // namespace fishtank
