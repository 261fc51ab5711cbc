// When the trajectory gets its frames: at the multiples of N steps; a
// recording from the start of a pour holds no empty frame (ASE cannot read
// one) and ends with the final state;
// none comes before --record-from; a constant-count recording waits for the
// pour to finish and ends, saying why, when the count changes; a write that
// fails when the file is closed (a full disk) fails the recording, said.

#include "server/export/trajectory_recorder.h"

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace fishtank;

namespace {

struct Frame {
  std::uint64_t step = 0;
  std::uint32_t declared = 0;  // NUMBER OF ATOMS
  std::uint32_t rows = 0;      // atom lines that follow
};

// Each frame's step, declared count and rows (the rows of a frame run up to the next "ITEM: TIMESTEP").
std::vector<Frame> read_frames(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<Frame> frames;
  bool in_atoms = false;
  for (std::string line; std::getline(in, line);) {
    if (line == "ITEM: TIMESTEP") {
      frames.emplace_back();
      std::getline(in, line);
      frames.back().step = std::stoull(line);
      in_atoms = false;
    } else if (line == "ITEM: NUMBER OF ATOMS") {
      std::getline(in, line);
      frames.back().declared = static_cast<std::uint32_t>(std::stoul(line));
    } else if (line.rfind("ITEM: ATOMS", 0) == 0) {
      in_atoms = true;
    } else if (in_atoms) {
      ++frames.back().rows;
    }
  }
  return frames;
}

std::filesystem::path temp_file(const std::string& name) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove(path);
  return path;
}

// Steps the world, offering the recorder a frame after every step; returns the last non-empty note.
std::string run(World& world, TrajectoryRecorder& recorder, int steps) {
  std::string note;
  for (int s = 0; s < steps; ++s) {
    world.step();
    if (std::string n = recorder.at_step_boundary(world); !n.empty()) note = n;
  }
  return note;
}

}  // namespace

TEST_CASE("a recording from the start of a pour has no empty frame and ends with the final state", "[export][record]") {
  World world(PhysicsParams{}, kSseKernels, 1, 3);
  world.add_balls(300);
  const auto path = temp_file("fishtank-record-pour.lammpstrj");
  {
    TrajectoryRecorder recorder({path.string(), 50, 0.0, false});
    REQUIRE(recorder.open().empty());
    CHECK(recorder.at_step_boundary(world).empty());  // t = 0: nothing poured yet, nothing written
    CHECK(recorder.frames() == 0);
    CHECK(run(world, recorder, 420).empty());
    CHECK(recorder.finish(world).empty());
    CHECK(recorder.finish(world).empty());  // the final state once only
    CHECK_FALSE(recorder.failed());
  }
  const std::vector<Frame> frames = read_frames(path);
  REQUIRE(frames.size() >= 8);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    INFO("frame " << f << " at step " << frames[f].step);
    CHECK(frames[f].declared > 0);
    CHECK(frames[f].rows == frames[f].declared);
    if (f > 0) CHECK(frames[f].declared >= frames[f - 1].declared);  // a pour only adds
    if (f + 1 < frames.size()) CHECK(frames[f].step % 50 == 0);
  }
  CHECK(frames.front().step == 50);  // step 0 had no ball in yet
  CHECK(frames.back().step == world.steps());
  CHECK(frames.back().declared == world.ball_count());
}

TEST_CASE("a step offered again, as a paused loop does, is recorded once", "[export][record]") {
  World world(PhysicsParams{}, kSseKernels, 1, 3);
  world.add_balls(30);
  const auto path = temp_file("fishtank-record-paused.lammpstrj");
  {
    TrajectoryRecorder recorder({path.string(), 10, 0.0, false});
    REQUIRE(recorder.open().empty());
    run(world, recorder, 20);
    for (int round = 0; round < 5; ++round) CHECK(recorder.at_step_boundary(world).empty());  // paused at step 20
    CHECK(recorder.frames() == 2);
    CHECK(recorder.finish(world).empty());
    CHECK(recorder.frames() == 2);  // the final state is the last frame already
  }
  const std::vector<Frame> frames = read_frames(path);
  REQUIRE(frames.size() == 2);
  CHECK(frames[0].step == 10);
  CHECK(frames[1].step == 20);
}

TEST_CASE("no frame is recorded before --record-from's simulated second", "[export][record]") {
  World world(PhysicsParams{}, kSseKernels, 1, 3);
  world.add_balls(30);
  const auto path = temp_file("fishtank-record-from.lammpstrj");
  const double from = 0.1;
  {
    TrajectoryRecorder recorder({path.string(), 20, from, false});
    REQUIRE(recorder.open().empty());
    run(world, recorder, 300);
  }
  const std::vector<Frame> frames = read_frames(path);
  REQUIRE_FALSE(frames.empty());
  CHECK(frames.front().step * world.dt() >= from);
  CHECK((frames.front().step - 20) * world.dt() < from);  // and the first comes at the first multiple past it
  for (const Frame& f : frames) CHECK(f.step % 20 == 0);
  for (std::size_t f = 1; f < frames.size(); ++f) CHECK(frames[f].step - frames[f - 1].step == 20);
}

TEST_CASE("a run that ends before --record-from's second records nothing, says why and fails", "[export][record]") {
  World world(PhysicsParams{}, kSseKernels, 1, 3);
  world.add_balls(30);
  const auto path = temp_file("fishtank-record-too-late.lammpstrj");
  TrajectoryRecorder recorder({path.string(), 20, 5.0, false});
  REQUIRE(recorder.open().empty());
  CHECK(run(world, recorder, 300).empty());
  const std::string note = recorder.finish(world);
  CHECK_THAT(note, Catch::StartsWith("no frame recorded: the run ended at t = 0.3") &&
                       Catch::EndsWith("s with 30 balls, before --record-from 5 s; " + path.string() + " is empty"));
  CHECK(recorder.failed());
  CHECK(recorder.frames() == 0);
}

TEST_CASE("a constant-count recording whose run ends while balls still pour in says that is why it is empty",
          "[export][record]") {
  World world(PhysicsParams{}, kSseKernels, 1, 3);
  world.add_balls(3000);
  const auto path = temp_file("fishtank-record-mid-pour.lammpstrj");
  TrajectoryRecorder recorder({path.string(), 20, 0.0, true});
  REQUIRE(recorder.open().empty());
  CHECK(run(world, recorder, 50).empty());
  REQUIRE(world.pending() > 0);
  CHECK_THAT(recorder.finish(world),
             Catch::Contains(" still queued to pour in (--record-constant-count waits for them); " + path.string() +
                             " is empty"));
  CHECK(recorder.failed());
}

TEST_CASE("a constant-count recording starts once the pour is in and ends, saying why, when the count changes",
          "[export][record]") {
  World world(PhysicsParams{}, kSseKernels, 1, 3);
  world.add_balls(300);
  const auto path = temp_file("fishtank-record-constant.lammpstrj");
  TrajectoryRecorder recorder({path.string(), 50, 0.0, true});
  REQUIRE(recorder.open().empty());
  while (world.pending() > 0 && world.steps() < 5000) {
    world.step();
    CHECK(recorder.at_step_boundary(world).empty());
    if (world.pending() > 0) CHECK(recorder.frames() == 0);
  }
  const std::uint64_t poured_at = world.steps();  // the first step after which nothing was queued
  REQUIRE(poured_at > 1);
  CHECK(run(world, recorder, 200).empty());
  REQUIRE(recorder.frames() > 0);
  world.add_balls(9);
  std::string note = run(world, recorder, 100);
  CHECK(note.find("ball count changed from 300 to 309") != std::string::npos);
  CHECK(note.find("--record-constant-count") != std::string::npos);
  CHECK(note.find(path.string()) != std::string::npos);
  const std::uint64_t frames_at_end = recorder.frames();
  CHECK(run(world, recorder, 200).empty());  // nothing more, and said once
  CHECK(recorder.finish(world).empty());
  CHECK(recorder.frames() == frames_at_end);
  CHECK_FALSE(recorder.failed());

  const std::vector<Frame> frames = read_frames(path);
  REQUIRE(frames.size() == frames_at_end);
  CHECK(frames.front().step == (poured_at + 49) / 50 * 50);  // the first multiple of 50 from then
  for (const Frame& f : frames) {
    CHECK(f.declared == 300);
    CHECK(f.rows == 300);
  }
}

TEST_CASE("without a path nothing is recorded and nothing fails", "[export][record]") {
  World world(PhysicsParams{}, kSseKernels, 1, 3);
  world.add_balls(10);
  TrajectoryRecorder recorder({"", 1, 0.0, false});
  CHECK(recorder.open().empty());
  CHECK(run(world, recorder, 30).empty());
  CHECK(recorder.finish(world).empty());
  CHECK(recorder.frames() == 0);
  CHECK_FALSE(recorder.failed());
}

TEST_CASE("a recording whose last frames cannot reach the disk says so when it finishes, and fails",
          "[export][record]") {
  if (!std::filesystem::exists("/dev/full")) {
    WARN("SKIPPED: no /dev/full here (every write to it fails, as on a full disk)");
    return;
  }
  World world(PhysicsParams{}, kSseKernels, 1, 3);
  world.add_balls(5);
  TrajectoryRecorder recorder({"/dev/full", 1000, 0.0, false});
  REQUIRE(recorder.open().empty());
  CHECK(run(world, recorder, 30).empty());  // a few small frames: all still in the C library's buffer
  const std::string note = recorder.finish(world);
  CHECK(note == "error while writing /dev/full; the recording's last frames are lost");
  CHECK(recorder.failed());
}
