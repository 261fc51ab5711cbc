// The frame cap sleeps only when the viewer is ahead of it, holds the rate
// without vsync, and never rushes frames out after a slow one.

#include "viewer/frame_pacer.h"

#include <catch2/catch.hpp>
#include <vector>

using fishtank::viewer::FramePacer;

namespace {

// Runs frames that each take `work(i)` seconds, sleeping as the pacer says
// plus `oversleep` (the OS wakes a thread late), for `seconds` of simulated
// time. Returns when each frame started.
template <typename Work>
std::vector<double> frame_starts(FramePacer& pacer, double seconds, Work work, double oversleep = 0.0) {
  std::vector<double> starts;
  double t = 0.0;
  for (int i = 0; t < seconds; ++i) {
    starts.push_back(t);
    t += work(i);
    const double sleep = pacer.sleep_seconds(t);
    REQUIRE(sleep >= 0.0);
    if (sleep > 0.0) t += sleep + oversleep;
  }
  return starts;
}

}  // namespace

TEST_CASE("a 60 fps cap over 1 s of 1 ms frames starts 60 +- 1 frames") {
  FramePacer pacer(60);
  const auto starts = frame_starts(pacer, 1.0, [](int) { return 0.001; });
  CHECK(starts.size() >= 59);
  CHECK(starts.size() <= 61);
}

TEST_CASE("a 30 fps cap over 2 s of 1 ms frames starts 60 +- 1 frames") {
  FramePacer pacer(30);
  const auto starts = frame_starts(pacer, 2.0, [](int) { return 0.001; });
  CHECK(starts.size() >= 59);
  CHECK(starts.size() <= 61);
}

TEST_CASE("waking late from each sleep does not lower the capped rate") {
  FramePacer pacer(60);
  // 0.3 ms late every frame would lose a frame in 50 if sleeps were relative.
  const auto starts = frame_starts(
      pacer, 10.0, [](int) { return 0.002; }, 0.0003);
  CHECK(starts.size() >= 599);
  CHECK(starts.size() <= 601);
}

TEST_CASE("an uncapped pacer never sleeps") {
  FramePacer pacer(0);
  double t = 0.0;
  for (int i = 0; i < 1000; ++i) {
    t += (i % 7) * 1e-4;  // includes frames of zero length
    CHECK(pacer.sleep_seconds(t) == 0.0);
  }
}

TEST_CASE("frames slower than the cap never sleep") {
  FramePacer pacer(60);
  double t = 0.0;
  for (int i = 0; i < 100; ++i) CHECK(pacer.sleep_seconds(t += 0.05) == 0.0);
}

TEST_CASE("a slow frame is not followed by a catch-up burst") {
  FramePacer pacer(60);
  const auto starts = frame_starts(pacer, 2.0, [](int i) { return i == 30 ? 0.2 : 0.001; });
  REQUIRE(starts.size() > 40);
  CHECK(starts[31] - starts[30] == Approx(0.2));  // the slow frame itself, with no sleep after it
  for (std::size_t i = 31; i + 1 < starts.size(); ++i) CHECK(starts[i + 1] - starts[i] >= 1.0 / 60.0 - 1e-9);
  // The 0.2 s is lost, not made up: the slow frame, and 60 a second over the other 1.8 s.
  CHECK(starts.size() >= 107);
  CHECK(starts.size() <= 110);
}

TEST_CASE("Mesa's CPU renderers get the lower default cap, a GPU the usual one, a given cap always wins") {
  using fishtank::viewer::choose_max_fps;
  using fishtank::viewer::is_software_renderer;
  CHECK(is_software_renderer("llvmpipe (LLVM 15.0.6, 256 bits)"));
  CHECK(is_software_renderer("softpipe"));
  CHECK_FALSE(is_software_renderer("NVIDIA GeForce RTX 3060/PCIe/SSE2"));
  CHECK_FALSE(is_software_renderer("Mesa Intel(R) UHD Graphics 620 (KBL GT2)"));
  CHECK_FALSE(is_software_renderer(nullptr));
  CHECK(choose_max_fps(-1, "llvmpipe (LLVM 15.0.6, 256 bits)") == fishtank::viewer::kSoftwareMaxFps);
  CHECK(choose_max_fps(-1, "NVIDIA GeForce RTX 3060/PCIe/SSE2") == fishtank::viewer::kDefaultMaxFps);
  CHECK(choose_max_fps(-1, nullptr) == fishtank::viewer::kDefaultMaxFps);
  CHECK(choose_max_fps(0, "llvmpipe (LLVM 15.0.6, 256 bits)") == 0);
  CHECK(choose_max_fps(144, "llvmpipe (LLVM 15.0.6, 256 bits)") == 144);
}
