// Google Benchmark of whole physics steps, so ratios come from one process:
//   step_tank/<variant>/<threads>  every kernel set on one settled 6000-ball tank,
//                                  each stepped kTankSteps steps per repetition
//                                  from it, so all cover the same stretch of
//                                  simulated time
//   build_lists/<variant>          one neighbour-list build of that tank, one thread,
//                                  and the SIMD blocks per ball its lists ask for
//   step_wide/sse/<balls>          the wide scene at 10^4, 10^5 and 10^6 balls
//                                  (SSE on every core), each stepped 50 steps
//                                  per repetition so all sizes advance through
//                                  the same stretch of simulated time
//
// A shared virtual machine's speed drifts over minutes.
// Run with random interleaving and repetitions so every case samples the same
// drift, and compare medians; --benchmark_filter=step_tank or step_wide picks
// a family (the wide worlds take a few minutes to build). The run also says
// where the host placed the cores (line_transfer.h), which moves the small
// wide scene's figure, before (in its context) and after (on stderr).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/fp_env.h"
#include "server/bench/line_transfer.h"
#include "server/bench/scenes.h"
#include "server/physics/world.h"

namespace {

using fishtank::World;

// The settled 6000-ball tank every benchmark starts from, made once.
const std::vector<fishtank::BallView>& settled_tank() {
  static const std::vector<fishtank::BallView> balls = [] {
    std::fprintf(stderr, "settling the 6000-ball tank every step_tank case starts from...\n");
    fishtank::SceneSpec spec;  // tank, 6000 balls
    World world(fishtank::PhysicsParams{}, fishtank::kSseKernels, fishtank::WorkerPool::hardware_threads(), 1);
    fishtank::populate(world, spec);
    fishtank::TunedStepper untuned(world, false);
    const fishtank::SettleReport report = fishtank::settle(untuned, spec);
    // scripts/callgrind-step switches instrumentation on at this line.
    std::fprintf(stderr, "settled: %u balls, %.1f simulated s, %s\n", world.ball_count(), report.sim_seconds,
                 report.settled ? "at rest" : "time limit reached");
    std::vector<fishtank::BallView> state;
    for (std::uint32_t id = 0; id < world.ball_count(); ++id) state.push_back(world.ball(id));
    return state;
  }();
  return balls;
}

// The timed loop of a step benchmark: the rate, and how often the lists were
// rebuilt while it ran and what share of the time that took (a rebuild costs
// several steps, and how often one is due depends on the scene), with what
// the strayed balls' checks and each rebuild cost.
void time_steps(benchmark::State& state, World& world) {
  const std::uint64_t rebuilds_before = world.rebuilds(), kept_before = world.lists_kept_by_checks();
  const std::uint64_t checked_before = world.strayed_balls_checked();
  const fishtank::PhaseSeconds phases_before = world.phase_seconds();
  for (auto _ : state) world.step();
  state.counters["ball_steps_per_s"] =
      benchmark::Counter(double(state.iterations()) * world.ball_count(), benchmark::Counter::kIsRate);
  const fishtank::PhaseSeconds& phases = world.phase_seconds();
  const double between_passes = phases.neighbours - phases_before.neighbours;
  const double checks = phases.stray_checks - phases_before.stray_checks;
  const double steps = double(state.iterations()), rebuilds = double(world.rebuilds() - rebuilds_before);
  state.counters["rebuilds_per_kstep"] = 1000.0 * rebuilds / steps;
  state.counters["kept_per_kstep"] = 1000.0 * double(world.lists_kept_by_checks() - kept_before) / steps;
  state.counters["rebuild_share"] = between_passes / (between_passes + phases.step_pass - phases_before.step_pass);
  state.counters["far_per_step"] = double(world.strayed_balls_checked() - checked_before) / steps;
  state.counters["check_us_per_step"] = 1e6 * checks / steps;
  if (rebuilds > 0) state.counters["rebuild_us"] = 1e6 * (between_passes - checks) / rebuilds;
}

// Steps per repetition of step_tank, the same for every variant. Timed for a
// minimum time instead, the faster variants stepped further from the settled
// state, into stretches where the creeping pile needs its lists rebuilt more
// often, so the ratio between them measured the pile as well as the code.
constexpr benchmark::IterationCount kTankSteps = 4000;

void step_tank(benchmark::State& state, const fishtank::Kernels& kernels) {
  fishtank::enable_flush_denormals_to_zero();
  const int threads = static_cast<int>(state.range(0));
  World world(fishtank::PhysicsParams{}, kernels, threads, 1);
  for (const fishtank::BallView& b : settled_tank())
    world.place_ball(b.kind, {b.pos.x, b.pos.y, b.pos.z}, {b.vel.x, b.vel.y, b.vel.z});
  for (int s = 0; s < 50; ++s) world.step();  // first lists, warm caches
  time_steps(state, world);
}

// SIMD blocks per ball that the lists ask for, for the ways of filling lanes
// the technical report compares (section 4 and 6.1): one ball's neighbours
// four or eight at a time, two balls side by side four each (as long as the
// longer list), four balls in lockstep one each as they come, and four or
// eight in lockstep by neighbour count within each step batch (the SSE and
// AVX2 kernels).
void report_block_counts(benchmark::State& state, const std::uint32_t* counts, std::uint32_t n) {
  const auto blocks = [](std::uint32_t count, std::uint32_t lanes) { return (count + lanes - 1) / lanes; };
  double neighbours = 0, one_ball_4 = 0, one_ball_8 = 0, two_balls = 0, four_balls = 0, four_by_count = 0,
         eight_by_count = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    neighbours += counts[i];
    one_ball_4 += blocks(counts[i], 4);
    one_ball_8 += blocks(counts[i], 8);
    if (i % 2 == 0 && i + 1 < n) two_balls += blocks(std::max(counts[i], counts[i + 1]), 4);
    if (i % 4 == 0 && i + 3 < n) four_balls += *std::max_element(counts + i, counts + i + 4);
  }
  for (std::uint32_t batch = 0; batch < n; batch += fishtank::kStepBatch) {
    std::vector<std::uint32_t> sorted(counts + batch, counts + std::min(n, batch + fishtank::kStepBatch));
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t g = 3; g < sorted.size() + 3; g += 4) four_by_count += sorted[std::min(g, sorted.size() - 1)];
    for (std::size_t g = 7; g < sorted.size() + 7; g += 8) eight_by_count += sorted[std::min(g, sorted.size() - 1)];
  }
  state.counters["neighbours"] = neighbours / n;
  state.counters["blocks4_one_ball"] = one_ball_4 / n;
  state.counters["blocks8_one_ball"] = one_ball_8 / n;
  state.counters["blocks8_two_balls"] = two_balls / n;
  state.counters["blocks4_four_balls"] = four_balls / n;
  state.counters["blocks4_four_balls_by_count"] = four_by_count / n;
  state.counters["blocks8_eight_balls_by_count"] = eight_by_count / n;
}

// Per ball, as a SIMD build laid the lists out: contacts, blocks, and the
// blocks in which some lane touches, whose force the step computes.
void report_layout(benchmark::State& state, const fishtank::NeighbourList& list, const fishtank::Float4* pos,
                   std::uint32_t n, std::uint32_t lanes) {
  double contacts = 0, blocks = 0, force_blocks = 0;
  for (std::uint32_t batch = 0; batch < n; batch += fishtank::kStepBatch) {
    const std::uint32_t* block = list.neighbours() + std::size_t(batch) * list.stride();
    const std::uint32_t* const order = list.batch_order();
    const std::uint32_t grouped = fishtank::grouped_length(fishtank::batch_end(batch, n) - batch, lanes);
    for (std::uint32_t place = batch; place < batch + grouped; place += lanes)
      for (std::uint32_t k = 0; k < list.group_blocks()[place / lanes]; ++k, block += lanes) {
        int touching = 0;
        for (std::uint32_t l = 0; l < lanes; ++l) {
          const fishtank::Float4 &pi = pos[order[place + l]], &pj = fishtank::listed(pos, block[l]);
          const float dx = pj.x - pi.x, dy = pj.y - pi.y, dz = pj.z - pi.z, reach = pi.w + pj.w;
          const bool touches = dx * dx + dy * dy + dz * dz < reach * reach;
          touching += touches;
          contacts += touches && (l == 0 || order[place + l] != order[place + l - 1]);  // a padded lane repeats
        }
        blocks += 1;
        force_blocks += touching > 0;
      }
  }
  state.counters["contacts"] = contacts / n;
  state.counters["blocks"] = blocks / n;
  state.counters["force_blocks"] = force_blocks / n;
}

void build_lists(benchmark::State& state, const fishtank::Kernels& kernels) {
  fishtank::PhysicsParams params;
  fishtank::AlignedVector<fishtank::Float4> unsorted;
  for (const fishtank::BallView& b : settled_tank()) unsorted.push_back(b.pos);
  const auto n = static_cast<std::uint32_t>(unsorted.size());
  unsorted.resize(n + fishtank::kGhostSlots, fishtank::kGhostPos);
  fishtank::NeighbourList list;
  list.configure(params.tank, fishtank::starting_skin(params));
  std::vector<std::uint32_t> order;
  list.sort(unsorted.data(), n, order);
  fishtank::AlignedVector<fishtank::Float4> pos(unsorted);
  for (std::uint32_t k = 0; k < n; ++k) pos[k] = unsorted[order[k]];
  list.reserve(n, 32, kernels.list_lanes);
  const fishtank::ListBuild build = list.build_view(pos.data(), n);
  for (auto _ : state) benchmark::DoNotOptimize(kernels.build_lists(build, 0, n));
  report_block_counts(state, list.counts(), n);
  if (kernels.list_lanes > 1) report_layout(state, list, pos.data(), n, kernels.list_lanes);
}

// One wide-scene world per size, dropped and run for the scene's 4 simulated
// seconds on first use, then stepped on by every repetition.
World& wide_world(std::uint32_t balls) {
  static std::map<std::uint32_t, std::unique_ptr<World>> worlds;
  std::unique_ptr<World>& world = worlds[balls];
  if (!world) {
    std::fprintf(stderr, "building the %u-ball wide scene...\n", balls);
    fishtank::SceneSpec spec;
    spec.name = "wide";
    spec.balls = balls;
    fishtank::PhysicsParams params;
    params.tank = fishtank::scene_tank(spec);
    world = std::make_unique<World>(params, fishtank::kSseKernels, fishtank::WorkerPool::hardware_threads(), 1);
    fishtank::populate(*world, spec);
    fishtank::TunedStepper untuned(*world, false);
    fishtank::settle(untuned, spec);
  }
  return *world;
}

void step_wide(benchmark::State& state) {
  fishtank::enable_flush_denormals_to_zero();
  World& world = wide_world(static_cast<std::uint32_t>(state.range(0)));
  time_steps(state, world);
}

// --help: what this program times and how to call it, then Google Benchmark's own flags.
void print_help() {
  std::printf(
      "fishtank-bench-variants: Google Benchmark of whole physics steps, every kernel set in one process.\n"
      "  step_tank/<variant>/<threads>  the settled 6000-ball tank (scalar, sse, avx2; 1 thread and every core)\n"
      "  build_lists/<variant>          one neighbour-list build of that tank\n"
      "  step_wide/sse/<balls>          the wide scene at 10^4, 10^5 and 10^6 balls (minutes to build)\n"
      "Example: fishtank-bench-variants --benchmark_filter=step_tank --benchmark_repetitions=5 \\\n"
      "           --benchmark_enable_random_interleaving=true\n"
      "scripts/callgrind-step counts its instructions per ball-step under valgrind.\n\n");
  benchmark::PrintDefaultHelp();
}

}  // namespace

int main(int argc, char** argv) {
  const int cores = fishtank::WorkerPool::hardware_threads();
  auto add = [cores](const char* name, const fishtank::Kernels& kernels, bool threaded) {
    auto* b = benchmark::RegisterBenchmark(name, step_tank, std::cref(kernels));
    b->Arg(1)->Unit(benchmark::kMicrosecond)->Iterations(kTankSteps);
    if (threaded && cores > 1) b->Arg(cores);
  };
  add("step_tank/scalar", fishtank::kScalarKernels, false);
  add("step_tank/sse", fishtank::kSseKernels, true);
  if (fishtank::cpu_has_avx2()) add("step_tank/avx2", fishtank::kAvx2Kernels, true);
  for (const fishtank::Kernels* kernels :
       {&fishtank::kScalarKernels, &fishtank::kSseKernels, &fishtank::kAvx2Kernels}) {
    if (kernels == &fishtank::kAvx2Kernels && !fishtank::cpu_has_avx2()) continue;
    benchmark::RegisterBenchmark((std::string("build_lists/") + kernels->variant).c_str(), build_lists,
                                 std::cref(*kernels))
        ->Unit(benchmark::kMicrosecond);
  }
  benchmark::RegisterBenchmark("step_wide/sse", step_wide)
      ->Arg(10000)
      ->Arg(100000)
      ->Arg(1000000)
      ->Iterations(50)
      ->Unit(benchmark::kMillisecond);
  benchmark::Initialize(&argc, argv, print_help);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  // The cores' placement, which moves the small scenes' two-thread figures
  // (line_transfer.h): in the run's context before, on stderr after.
  auto placement = [] {
    const std::optional<fishtank::LineTransfer> t = fishtank::time_line_transfer();
    if (!t) return std::string("not timed: fewer than two CPUs");
    char text[64];
    std::snprintf(text, sizeof text, "%.0f ns between CPUs %d and %d", t->ns, t->cpu_a, t->cpu_b);
    return std::string(text);
  };
  benchmark::AddCustomContext("line_transfer_before", placement());
  // A filter that matches nothing ran nothing: a script must not read that as success.
  const bool ran = benchmark::RunSpecifiedBenchmarks() > 0;
  if (ran) std::fprintf(stderr, "line_transfer_after: %s\n", placement().c_str());
  benchmark::Shutdown();
  return ran ? 0 : 1;
}
