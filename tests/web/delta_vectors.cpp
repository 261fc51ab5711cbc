// Writes delta snapshots coded by the server's encoder (protocol/snapshot_delta.h),
// one JSON object a line, for delta_test.mjs to decode with the page's twin
// decoder (web/src/delta.ts) and compare with the positions coded.
//
// Cases: a still pile, jitter of a quantum or two, balls that jump, balls that
// move steadily (coded against a prediction from prior to base), balls added
// and removed, values at the ends of the range, and gaps of several ticks.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "protocol/snapshot_delta.h"

namespace {

using Values = std::vector<std::uint16_t>;

std::string json(const char* name, const std::uint8_t* data, std::size_t n) {
  std::string s = std::string("\"") + name + "\":[";
  for (std::size_t i = 0; i < n; ++i) s += (i ? "," : "") + std::to_string(data[i]);
  return s + "]";
}
std::string json(const char* name, const Values& v) {
  std::string s = std::string("\"") + name + "\":[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + std::to_string(v[i]);
  return s + "]";
}

std::uint16_t clamp16(long v) { return static_cast<std::uint16_t>(std::clamp(v, 0L, 65535L)); }

// prior (may be empty: no prediction) at prior_tick, base at base_tick, now at tick.
void emit(const std::string& name, const Values& prior, std::uint32_t prior_tick, const Values& base,
          std::uint32_t base_tick, const Values& now, std::uint32_t tick) {
  fishtank::protocol::DeltaReference ref;
  ref.base = base.data();
  ref.base_count = static_cast<std::uint32_t>(base.size() / 3);
  ref.base_tick = base_tick;
  if (!prior.empty()) {
    ref.prior = prior.data();
    ref.prior_count = static_cast<std::uint32_t>(prior.size() / 3);
    ref.prior_tick = prior_tick;
  }
  fishtank::protocol::PositionsDelta d;
  fishtank::protocol::encode_positions_delta(ref, tick, now.data(), static_cast<std::uint32_t>(now.size() / 3), d);
  std::printf("{\"name\":\"%s\",\"tick\":%u,\"baseTick\":%u,\"priorTick\":%u,%s,%s,%s,%s,%s}\n", name.c_str(), tick,
              base_tick, prior_tick, json("prior", prior).c_str(), json("base", base).c_str(), json("now", now).c_str(),
              json("unchanged", d.unchanged.data(), d.unchanged.size()).c_str(),
              json("changes", d.changes.data(), d.changes.size()).c_str());
}

}  // namespace

int main() {
  std::mt19937 rng(42);
  std::uniform_int_distribution<int> any(0, 65535), jitter(-2, 2), pick(0, 9), velocity(-400, 400);
  const std::uint32_t n = 500;

  Values prior(3 * n), vel(3 * n);
  for (auto& q : prior) q = static_cast<std::uint16_t>(any(rng));
  for (auto& v : vel) v = static_cast<std::uint16_t>(velocity(rng) + 400);  // stored offset by 400
  // Half the balls move steadily, the rest sit still; the base is one tick on.
  auto steady = [&](const Values& from, long ticks) {
    Values out(from);
    for (std::uint32_t i = 0; i < 3 * n; ++i)
      if ((i / 3) % 2 == 0) out[i] = clamp16(from[i] + ticks * (static_cast<long>(vel[i]) - 400));
    return out;
  };
  const Values base = steady(prior, 1);

  emit("still pile", {}, 0, base, 10, base, 11);

  Values jittered(base);
  for (auto& q : jittered) q = clamp16(q + (pick(rng) >= 7 ? jitter(rng) : 0));
  emit("jitter", {}, 0, base, 10, jittered, 11);

  Values jumped(jittered);
  for (std::uint32_t b = 0; b < n; b += 7) jumped[3 * b + 1] = static_cast<std::uint16_t>(any(rng));
  emit("jumps (a high exp-Golomb order)", {}, 0, base, 10, jumped, 11);

  // A few far jumps among jitter: order 0, so each jump's code is longer than 32 bits.
  Values far(jittered);
  for (std::uint32_t b = 0; b < n; b += 97) far[3 * b + 2] = static_cast<std::uint16_t>(base[3 * b + 2] ^ 0xc000);
  emit("far jumps among jitter (codes over 32 bits)", {}, 0, base, 10, far, 11);

  // Predicted from prior (tick 9) to base (tick 10), three ticks ahead, with a small change of velocity.
  Values moving = steady(prior, 4);
  for (auto& q : moving) q = clamp16(q + jitter(rng));
  emit("steady motion, predicted", prior, 9, base, 10, moving, 13);
  // A prior two ticks before the base: the prediction divides and truncates.
  emit("steady motion, prior two ticks back", prior, 8, base, 10, moving, 11);

  Values grown(jittered);
  for (int v = 0; v < 3 * 37; ++v) grown.push_back(static_cast<std::uint16_t>(any(rng)));
  emit("balls added", prior, 9, base, 10, grown, 11);

  const Values shrunk(jittered.begin(), jittered.begin() + 3 * 123);
  emit("balls removed", prior, 9, base, 10, shrunk, 11);

  Values ends(base);
  for (std::uint32_t b = 0; b < n; b += 3) ends[3 * b] = (b % 2) ? 0 : 65535;
  emit("values at the ends of the range", prior, 9, base, 10, ends, 12);
  return 0;
}
