// One thread's CPU time per World::step over a dumped state, for scripts/figures-step-harness.
// It uses only the World calls every build since the exact contact's first has, so the script
// compiles it against each build it compares (its source tree and its libraries).
//
//   step_harness STATE.csv SCENE BALLS scalar|sse|avx2 STEPS DT
//
// STATE.csv: fishtank-server --dump's columns (x,y,z,vx,vy,vz,diameter,mass). Prints
// "cpu_ns_per_ball_step N".
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>

#include "common/fp_env.h"
#include "server/physics/world.h"
#include "server/scenes/scene_presets.h"

namespace {

double thread_seconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: step_harness STATE.csv SCENE BALLS scalar|sse|avx2 STEPS DT\n");
    return 2;
  }
  fishtank::enable_flush_denormals_to_zero();
  fishtank::SceneSpec spec;
  spec.name = argv[2];
  spec.balls = std::atoi(argv[3]);
  fishtank::PhysicsParams params;
  params.tank = fishtank::scene_tank(spec);
  params.dt = static_cast<float>(std::atof(argv[6]));
  const char* kernel = argv[4];
  const fishtank::Kernels& kernels = !std::strcmp(kernel, "scalar") ? fishtank::kScalarKernels
                                     : !std::strcmp(kernel, "sse")  ? fishtank::kSseKernels
                                                                    : fishtank::kAvx2Kernels;
  fishtank::World world(params, kernels, 1, 1);
  std::FILE* state = std::fopen(argv[1], "r");
  if (!state) {
    std::fprintf(stderr, "step_harness: cannot read %s\n", argv[1]);
    return 1;
  }
  char header[512];
  if (!std::fgets(header, sizeof header, state)) return 1;
  float x, y, z, vx, vy, vz, diameter, mass;
  while (std::fscanf(state, "%f,%f,%f,%f,%f,%f,%f,%f", &x, &y, &z, &vx, &vy, &vz, &diameter, &mass) == 8)
    world.place_ball(int(diameter + 0.5f) - 1, {x, y, z}, {vx, vy, vz});  // kinds are diameters 1, 2, 3
  std::fclose(state);
  for (int s = 0; s < 20; ++s) world.step();  // first lists, warm caches
  const int steps = std::atoi(argv[5]);
  const double start = thread_seconds();
  for (int s = 0; s < steps; ++s) world.step();
  const double seconds = thread_seconds() - start;
  std::printf("cpu_ns_per_ball_step %.3f\n", 1e9 * seconds / (double(steps) * world.ball_count()));
  return 0;
}
