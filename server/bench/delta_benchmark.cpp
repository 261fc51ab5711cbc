// Google Benchmark of the snapshot delta coder (protocol/snapshot_delta.h) on
// positions from real scenes, a sixtieth of a simulated second apart as a
// viewer at 60 snapshots/s gets them, each coded against the one before with
// the one before that as its prior:
//   delta_encode/wide/100000   the wide scene's lattice at 2 simulated s, falling and splashing
//   delta_decode/wide/100000   the same snapshot decoded, as a viewer does
//   delta_encode/tank/6000     the product's tank settled: most balls still, some jittering
//   delta_decode/tank/6000
// The server codes a frame per acknowledged base on its io thread; the GLFW
// viewer decodes every one. --write-wide DIR writes the wide case's base,
// prior, snapshot and delta as raw little-endian files and exits, so that
// scripts/figures-watching can time the page's twin (web/src/delta.ts) on them.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/fp_env.h"
#include "protocol/snapshot_delta.h"
#include "server/bench/scenes.h"
#include "server/net/snapshot_encoder.h"
#include "server/physics/world.h"

namespace {

using fishtank::World;

// The snapshots' ticks: each coded against the one before, with the one before that as its prior.
constexpr std::uint32_t kPriorTick = 1, kBaseTick = 2, kNowTick = 3;

struct Sequence {
  std::uint32_t balls = 0;
  std::vector<std::uint16_t> prior, base, now;  // 3 quantised values per ball, in id order
};

// Three snapshots of the scene a sixtieth of a simulated second apart, from `from_seconds` on
// (0: once settled).
Sequence snapshots(const char* scene, std::uint32_t balls, double from_seconds) {
  std::fprintf(stderr, "running the %u-ball %s scene for its snapshots...\n", balls, scene);
  fishtank::SceneSpec spec;
  spec.name = scene;
  spec.balls = balls;
  fishtank::PhysicsParams params;
  params.tank = fishtank::scene_tank(spec);
  World world(params, fishtank::kSseKernels, fishtank::WorkerPool::hardware_threads(), 1);
  fishtank::populate(world, spec);
  if (from_seconds > 0.0) {
    while (world.time() < from_seconds) world.step();
  } else {
    fishtank::TunedStepper untuned(world, false);
    fishtank::settle(untuned, spec);
  }
  const int steps_apart = static_cast<int>(std::lround(1.0 / 60.0 / world.dt()));
  // Captured as the server captures them.
  fishtank::net::SnapshotEncoder capture;
  fishtank::protocol::SnapshotHeader header;
  header.tank = world.params().tank;
  Sequence s;
  s.balls = world.ball_count();
  for (std::vector<std::uint16_t>* snapshot : {&s.prior, &s.base, &s.now}) {
    for (int i = 0; i < steps_apart; ++i) world.step();
    *snapshot = capture.encode(world, header)->quantised;
  }
  return s;
}

enum class Scene { wide, tank };

const Sequence& sequence(Scene scene) {
  if (scene == Scene::wide) {
    static const Sequence wide = snapshots("wide", 100000, 2.0);
    return wide;
  }
  static const Sequence tank = snapshots("tank", 6000, 0.0);
  return tank;
}

fishtank::protocol::DeltaReference reference(const Sequence& s) {
  return {s.base.data(), s.balls, kBaseTick, s.prior.data(), s.balls, kPriorTick};
}

void code(const Sequence& s, fishtank::protocol::PositionsDelta& delta) {
  fishtank::protocol::encode_positions_delta(reference(s), kNowTick, s.now.data(), s.balls, delta);
}

void report(benchmark::State& state, const Sequence& s, std::size_t bytes) {
  state.counters["balls"] = s.balls;
  state.counters["bytes_per_ball"] = double(bytes) / s.balls;
  state.counters["ns_per_ball"] = benchmark::Counter(double(state.iterations()) * s.balls,
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void delta_encode(benchmark::State& state, Scene scene) {
  const Sequence& s = sequence(scene);
  fishtank::protocol::PositionsDelta delta;
  for (auto _ : state) {
    code(s, delta);
    benchmark::DoNotOptimize(delta.changes.data());
  }
  report(state, s, delta.unchanged.size() + delta.changes.size());
}

void delta_decode(benchmark::State& state, Scene scene) {
  const Sequence& s = sequence(scene);
  fishtank::protocol::PositionsDelta delta;
  code(s, delta);
  std::vector<std::uint16_t> out(s.now.size());
  for (auto _ : state) {
    const std::string why = fishtank::protocol::decode_positions_delta(reference(s), kNowTick, delta.unchanged.data(),
                                                                       delta.unchanged.size(), delta.changes.data(),
                                                                       delta.changes.size(), s.balls, out.data());
    if (!why.empty() || out != s.now) throw std::runtime_error("the delta did not decode to its snapshot: " + why);
  }
  report(state, s, delta.unchanged.size() + delta.changes.size());
}

// The wide case's files for the page's decoder: prior.u16, base.u16, now.u16 (3 values per ball),
// unchanged.u8 and changes.u8, coded as delta_encode codes them (ticks kPriorTick, kBaseTick, kNowTick).
int write_wide(const std::string& dir) {
  const Sequence& s = sequence(Scene::wide);
  fishtank::protocol::PositionsDelta delta;
  code(s, delta);
  auto write = [&dir](const char* name, const void* data, std::size_t bytes) {
    std::ofstream out(dir + "/" + name, std::ios::binary);
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
    return bool(out);
  };
  const std::size_t values = s.now.size() * sizeof(std::uint16_t);
  if (write("prior.u16", s.prior.data(), values) && write("base.u16", s.base.data(), values) &&
      write("now.u16", s.now.data(), values) && write("unchanged.u8", delta.unchanged.data(), delta.unchanged.size()) &&
      write("changes.u8", delta.changes.data(), delta.changes.size()))
    return 0;
  std::fprintf(stderr, "fishtank-bench-delta: cannot write into %s\n", dir.c_str());
  return 1;
}

// --help: what this program times, then Google Benchmark's own flags.
void print_help() {
  std::printf(
      "fishtank-bench-delta: Google Benchmark of the snapshot delta coder on positions from real scenes.\n"
      "  delta_encode/wide/100000, delta_decode/wide/100000  the wide scene's lattice falling (2 simulated s)\n"
      "  delta_encode/tank/6000, delta_decode/tank/6000      the product's tank, settled\n"
      "  --write-wide DIR  write the wide case's snapshots and delta into DIR and exit (for the page's decoder)\n"
      "Example: fishtank-bench-delta --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true\n\n");
  benchmark::PrintDefaultHelp();
}

}  // namespace

int main(int argc, char** argv) {
  fishtank::enable_flush_denormals_to_zero();
  if (argc == 3 && std::strcmp(argv[1], "--write-wide") == 0) return write_wide(argv[2]);
  for (const auto& [scene, name] : {std::pair{Scene::wide, "wide/100000"}, std::pair{Scene::tank, "tank/6000"}}) {
    benchmark::RegisterBenchmark((std::string("delta_encode/") + name).c_str(), delta_encode, scene)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark((std::string("delta_decode/") + name).c_str(), delta_decode, scene)
        ->Unit(benchmark::kMicrosecond);
  }
  benchmark::Initialize(&argc, argv, print_help);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const bool ran = benchmark::RunSpecifiedBenchmarks() > 0;  // a filter that matches nothing fails
  benchmark::Shutdown();
  return ran ? 0 : 1;
}
