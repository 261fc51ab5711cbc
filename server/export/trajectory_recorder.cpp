#include "server/export/trajectory_recorder.h"

#include <cstdio>

#include "common/number_text.h"

namespace fishtank {

std::string TrajectoryRecorder::open() {
  ended_ = options_.path.empty();
  return ended_ ? "" : writer_.open(options_.path);
}

std::string TrajectoryRecorder::at_step_boundary(const World& world) {
  // Once a step: a paused loop comes round many times at the same one.
  return world.steps() % options_.every != 0 || last_step_ == world.steps() ? "" : write(world);
}

std::string TrajectoryRecorder::finish(const World& world) {
  if (options_.path.empty()) return "";
  const std::string note = last_step_ == world.steps() ? "" : write(world);
  if (failed_) return note;
  if (frames() > 0) return close_with(note);
  // An empty file is not what was asked for: say why, and fail like a write error.
  failed_ = true;
  char why[160];
  std::snprintf(why, sizeof why, "no frame recorded: the run ended at t = %.3f s with %u balls", world.time(),
                world.ball_count());
  const std::string reason = world.ball_count() == 0 ? ""
                             : world.time() < options_.from
                                 ? ", before --record-from " + number_text(options_.from) + " s"
                                 : ", " + std::to_string(world.pending()) +
                                       " still queued to pour in (--record-constant-count waits for them)";
  const std::string error = close_with("");
  return error.empty() ? why + reason + "; " + options_.path + " is empty" : error;
}

std::string TrajectoryRecorder::close_with(const std::string& note) {
  const std::string error = writer_.close();
  if (error.empty()) return note;
  failed_ = true;
  return error + "; the recording's last frames are lost";
}

std::string TrajectoryRecorder::write(const World& world) {
  if (ended_ || world.time() < options_.from || world.ball_count() == 0) return "";
  if (options_.constant_count) {
    if (frames() == 0 && world.pending() > 0) return "";  // balls are still pouring in
    if (frames() > 0 && world.ball_count() != count_) {
      ended_ = true;
      if (const std::string error = close_with(""); !error.empty()) return error;
      char why[256];
      std::snprintf(why, sizeof why,
                    "recording ended at t = %.3f s: the ball count changed from %u to %u, and "
                    "--record-constant-count keeps one count per file; ",
                    world.time(), count_, world.ball_count());
      return why + options_.path + " holds its " + std::to_string(frames()) +
             " frames; to record the new count, run the server again with --record-from past the change";
    }
    count_ = world.ball_count();
  }
  last_step_ = world.steps();
  std::string error = writer_.write_frame(world);
  if (!error.empty()) {
    ended_ = failed_ = true;
    error += "; recording stopped";
  }
  return error;
}

}  // namespace fishtank
