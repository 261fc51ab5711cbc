#pragma once
// A token bucket: `per_second` units flow in, at most `burst` are saved up, and
// it starts full. Used for the per-client command and ball allowances.

#include <algorithm>
#include <chrono>

namespace fishtank::net {

class RateBudget {
 public:
  using Clock = std::chrono::steady_clock;

  RateBudget(double per_second, double burst) : per_second_(per_second), burst_(burst), available_(burst) {}

  // Units available at `now` (a fraction while one refills).
  double available(Clock::time_point now) {
    refill(now);
    return available_;
  }
  // Takes `amount` when that much is available; otherwise takes nothing.
  bool take(double amount, Clock::time_point now) {
    refill(now);
    if (available_ < amount) return false;
    available_ -= amount;
    return true;
  }

 private:
  void refill(Clock::time_point now) {
    if (now > last_)
      available_ = std::min(burst_, available_ + per_second_ * std::chrono::duration<double>(now - last_).count());
    last_ = std::max(last_, now);
  }

  double per_second_, burst_, available_;
  Clock::time_point last_ = Clock::now();
};

}  // namespace fishtank::net
