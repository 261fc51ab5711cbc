// The frame-rate counter is measured over the last second of real frames (SPEC 5.1).

#include "viewer/frame_stats.h"

#include <catch2/catch.hpp>

using fishtank::viewer::FrameStats;

TEST_CASE("frames every 1/60 s read as 60 fps and 16.7 ms, CPU time as the mean per frame") {
  FrameStats stats;
  for (int i = 0; i <= 120; ++i) stats.frame_done(i / 60.0, 0.002, true);
  CHECK(stats.fps() == Approx(60.0f).epsilon(1e-3));
  CHECK(stats.frame_ms() == Approx(1000.0f / 60.0f).epsilon(1e-3));
  CHECK(stats.cpu_ms() == Approx(2.0f).epsilon(1e-3));
  CHECK(stats.total_frames() == 121);
}

TEST_CASE("the counter follows a change of rate within a second") {
  FrameStats stats;
  double t = 0.0;
  for (int i = 0; i < 120; ++i) stats.frame_done(t += 1.0 / 60.0, 0.0, true);
  for (int i = 0; i < 25; ++i) stats.frame_done(t += 1.0 / 20.0, 0.0, true);  // 1.25 s at 20 fps
  CHECK(stats.fps() == Approx(20.0f).epsilon(1e-3));
}

TEST_CASE("the exit summary counts only frames that drew the scene") {
  FrameStats stats;
  for (int i = 0; i < 10; ++i) stats.frame_done(i * 0.001, 0.0, false);  // waiting for the first snapshot
  for (int i = 0; i <= 30; ++i) stats.frame_done(1.0 + i / 30.0, 0.001, true);
  CHECK(stats.total_frames() == 31);
  CHECK(stats.total_seconds() == Approx(1.0));
  CHECK(stats.mean_cpu_ms() == Approx(1.0));
}

TEST_CASE("time minimised is left out of the summary's span, and before the first scene frame nothing is") {
  FrameStats stats;
  stats.not_drawn(0.0, 0.5);  // minimised before anything was drawn: the span has not begun
  for (int i = 0; i <= 30; ++i) stats.frame_done(1.0 + i / 30.0, 0.0, true);  // 2.0 s
  stats.not_drawn(2.0, 7.0);
  for (int i = 1; i <= 30; ++i) stats.frame_done(7.0 + i / 30.0, 0.0, true);  // to 8.0 s
  CHECK(stats.minimised_seconds() == Approx(5.0));
  CHECK(stats.total_seconds() == Approx(2.0));  // 1 to 8 s, less 5 s minimised
  CHECK(stats.total_frames() == 61);
}

TEST_CASE("frames drawn while waiting for a server are counted apart, for a viewer that never connects") {
  FrameStats stats;
  for (int i = 0; i <= 60; ++i) stats.frame_done(i / 30.0, 0.0, false);  // 2 s at 30 fps, nothing to draw
  CHECK(stats.total_frames() == 0);
  CHECK(stats.all_frames() == 61);
  CHECK(stats.all_seconds() == Approx(2.0));
}
